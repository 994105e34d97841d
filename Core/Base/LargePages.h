#pragma once
// LargePages: large buffers (CT voxels, DRR volumes) backed by the kernel's transparent huge pages where it offers
// them, so that allocating, first-touching and walking them costs a few hundred page faults and TLB entries instead
// of tens of thousands. On a 512x512x140 float CT this takes the zero-fill of a 147 MB buffer from about 0.1 s of
// page faults to a few milliseconds (docs/performance.md).

#include <cstddef>
#include <memory>
#include <vector>

namespace fct {

/// Asks the kernel to back [data, data + bytes) with transparent huge pages (Linux madvise MADV_HUGEPAGE on the
/// 2 MB-aligned part of the range). Only advice: does nothing on other systems, for small ranges, or when the kernel
/// declines; the memory stays valid either way.
void adviseLargePages(void* data, std::size_t bytes);

/// Replaces `values` by `count` copies of `fill` in a fresh allocation advised for large pages before it is first
/// touched. Throws std::bad_alloc like std::vector::assign when the memory is not available.
void assignWithLargePages(std::vector<float>& values, std::size_t count, float fill);

/// `count` floats of fresh, uninitialized memory advised for large pages and already mapped (for a buffer that is
/// about to be overwritten whole, which saves the fill). Throws std::bad_alloc when the memory is not available.
std::unique_ptr<float[]> allocateWithLargePages(std::size_t count);

}  // namespace fct
