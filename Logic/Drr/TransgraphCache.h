#pragma once
// TransgraphCache: stores a built Transgraph table on disk so that a second run with the same CT, view, expected
// pose and parameters loads it instead of building it (buildOrLoad).
//
// File `transgraph_<key as 16 hex digits>.fctg`, native byte order (little-endian on x86-64):
//   header: magic "FCTTGRPH", format version (u32), key (u64), layout (origin, R_ct_from_plane, plane w, minima,
//           spacing as f64; counts as i32), ray count (u64);
//   table:  ray count float32 values (s slowest, dt fastest);
//   trailer: 64-bit checksum of every byte before it.
// The key hashes the CT content (voxel values, dims, spacing, origin, direction), the view camera, the expected
// pose, the validity range, the parameters and the integrator id.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <filesystem>
#include <vector>

#include "Base/ProgressMonitor.h"
#include "Base/Result.h"
#include "Drr/Transgraph.h"
#include "Geometry/Camera.h"
#include "Image/Volume.h"

namespace fct {

/// Disk cache of Transgraph tables.
class TransgraphCache {
 public:
  /// A layout and its table, as read from a cache file.
  struct Entry {
    TransgraphLayout layout;
    std::vector<float> table;
  };

  /// Loads the table from `cacheFolder` (empty: defaultFolder()) when a valid file with this CT, view, pose and
  /// parameters exists; otherwise builds it (Transgraph::build) and saves it there. A corrupt or truncated cache file
  /// is rebuilt and named in a warning of the result; a cache that cannot be written is a warning too, not an error.
  /// Fails like Transgraph::build().
  static Result<Transgraph> buildOrLoad(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                                        const TransgraphParameters& parameters, Transgraph::RayIntegrator integrator,
                                        const std::filesystem::path& cacheFolder = {},
                                        const ProgressMonitor& monitor = {});

  /// $XDG_CACHE_HOME/fluoroct/transgraph, else $HOME/.cache/fluoroct/transgraph, else a folder in the temp directory.
  static std::filesystem::path defaultFolder();

  /// 64-bit key of everything the table depends on (see the file comment); maxRays is not part of it.
  static std::uint64_t key(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                           const TransgraphParameters& parameters);

  /// The cache file of `key` inside `folder`.
  static std::filesystem::path fileFor(const std::filesystem::path& folder, std::uint64_t key);

  /// Writes a table atomically (temporary file, then rename), creating the folder. Fails with the path and the
  /// reason when the folder or file cannot be written.
  static Status save(const std::filesystem::path& file, std::uint64_t key, const TransgraphLayout& layout,
                     const std::vector<float>& table);

  /// Reads a table; fails on a missing or unreadable file, a wrong magic, version or key, a size that does not match
  /// the header (truncated or padded), a checksum mismatch, or a layout different from `expectedLayout`.
  static Result<Entry> load(const std::filesystem::path& file, std::uint64_t key,
                            const TransgraphLayout& expectedLayout);
};

}  // namespace fct
