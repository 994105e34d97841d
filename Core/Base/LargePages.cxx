#include "Base/LargePages.h"

#include <algorithm>
#include <cstdint>
#include <thread>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace fct {

namespace {
/// Size of an x86-64 / AArch64 transparent huge page.
constexpr std::uintptr_t kLargePage_bytes = std::uintptr_t{2} << 20;
}  // namespace

void adviseLargePages(void* data, std::size_t bytes) {
#if defined(MADV_HUGEPAGE)
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kLargePage_bytes - 1) & ~(kLargePage_bytes - 1);
  const std::uintptr_t end = (begin + bytes) & ~(kLargePage_bytes - 1);
  if (end > first) (void)madvise(reinterpret_cast<void*>(first), end - first, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

namespace {

/// Advises [data, data + bytes) for large pages and has the kernel map it from several threads at once.
void mapWithLargePages(void* data, std::size_t bytes) {
  adviseLargePages(data, bytes);
#if defined(MADV_POPULATE_WRITE)
  // The kernel clears every new page on first touch; asking it to populate the pages from several threads spreads
  // that work over the cores instead of leaving it all to the fill below (refused on kernels before 5.14: no harm).
  const unsigned threads = std::min(std::max(1u, std::thread::hardware_concurrency()), 8u);
  if (bytes >= (kLargePage_bytes << 3) && threads > 1) {
    const auto begin = reinterpret_cast<std::uintptr_t>(data);
    const std::uintptr_t first = (begin + kLargePage_bytes - 1) & ~(kLargePage_bytes - 1);
    const std::uintptr_t end = (begin + bytes) & ~(kLargePage_bytes - 1);
    const std::uintptr_t share = ((end - first) / threads + kLargePage_bytes - 1) & ~(kLargePage_bytes - 1);
    std::vector<std::thread> workers;
    for (std::uintptr_t from = first; from < end; from += share) {
      workers.emplace_back([from, length = std::min(share, end - from)] {
        (void)madvise(reinterpret_cast<void*>(from), length, MADV_POPULATE_WRITE);
      });
    }
    for (std::thread& worker : workers) worker.join();
  }
#endif
}

}  // namespace

void assignWithLargePages(std::vector<float>& values, std::size_t count, float fill) {
  std::vector<float> fresh;
  fresh.reserve(count);  // a fresh mapping for a large count, not yet touched
  mapWithLargePages(fresh.data(), count * sizeof(float));
  fresh.assign(count, fill);
  values = std::move(fresh);
}

std::unique_ptr<float[]> allocateWithLargePages(std::size_t count) {
  std::unique_ptr<float[]> values(new float[count]);  // uninitialized: the caller writes every value
  mapWithLargePages(values.get(), count * sizeof(float));
  return values;
}

}  // namespace fct
