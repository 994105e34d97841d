#include "Drr/TransgraphCache.h"

#include "Base/AtomicFile.h"

#include <fmt/core.h>

#include <chrono>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string_view>
#include <system_error>

namespace fct {

namespace {

constexpr char kMagic[8] = {'F', 'C', 'T', 'T', 'G', 'R', 'P', 'H'};
constexpr std::uint32_t kVersion = 1;  // bump when the layout or the ray parameterization changes

// A fast 64-bit streaming hash (multiply-rotate over 8-byte words, splitmix64 finalizer). Not cryptographic: it
// detects changed inputs and corrupted files, which is all the cache needs.
class Hash64 {
 public:
  void bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::size_t i = 0;
    for (; i + 8 <= size; i += 8) {
      std::uint64_t word;
      std::memcpy(&word, p + i, 8);
      mixWord(word);
    }
    std::uint64_t tail = 0;
    if (size > i) std::memcpy(&tail, p + i, size - i);
    mixWord(tail ^ (static_cast<std::uint64_t>(size - i) << 56));
    m_length += size;
  }
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof(T));
  }
  void matrix(const double* data, std::size_t count) { bytes(data, count * sizeof(double)); }
  std::uint64_t digest() const {
    std::uint64_t z = m_state ^ m_length;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

 private:
  void mixWord(std::uint64_t word) {
    m_state ^= word * 0x87C37B91114253D5ULL;
    m_state = ((m_state << 31) | (m_state >> 33)) * 0x4CF5AD432745937FULL + 0x52DCE729ULL;
  }
  std::uint64_t m_state = 0x9E3779B97F4A7C15ULL;
  std::uint64_t m_length = 0;
};

// Appends plain values to a byte buffer.
class ByteWriter {
 public:
  template <typename T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    m_bytes.insert(m_bytes.end(), p, p + sizeof(T));
  }
  void putDoubles(const double* data, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) put(data[i]);
  }
  const std::vector<char>& bytes() const { return m_bytes; }

 private:
  std::vector<char> m_bytes;
};

// Reads plain values from a byte buffer; reports reading past the end.
class ByteReader {
 public:
  ByteReader(const char* data, std::size_t size) : m_data(data), m_size(size) {}
  template <typename T>
  bool get(T& v) {
    if (m_pos + sizeof(T) > m_size) return false;
    std::memcpy(&v, m_data + m_pos, sizeof(T));
    m_pos += sizeof(T);
    return true;
  }
  bool getDoubles(double* data, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      if (!get(data[i])) return false;
    }
    return true;
  }
 private:
  const char* m_data;
  std::size_t m_size;
  std::size_t m_pos = 0;
};

std::vector<char> headerBytes(std::uint64_t key, const TransgraphLayout& layout) {
  ByteWriter w;
  for (char c : kMagic) w.put(c);
  w.put(kVersion);
  w.put(key);
  w.putDoubles(layout.origin_ct_mm.data(), 3);
  w.putDoubles(layout.R_ct_from_plane.data(), 9);
  w.put(layout.front_w_mm);
  w.put(layout.back_w_mm);
  w.putDoubles(layout.min_mm.data(), 4);
  w.putDoubles(layout.step_mm.data(), 4);
  for (int c : layout.counts) w.put(static_cast<std::int32_t>(c));
  w.put(static_cast<std::uint64_t>(layout.rayCount()));
  return w.bytes();
}

bool sameLayout(const TransgraphLayout& a, const TransgraphLayout& b) {
  const double tol = 1e-9;
  return a.counts == b.counts && (a.origin_ct_mm - b.origin_ct_mm).cwiseAbs().maxCoeff() <= tol &&
         (a.R_ct_from_plane - b.R_ct_from_plane).cwiseAbs().maxCoeff() <= tol &&
         std::abs(a.front_w_mm - b.front_w_mm) <= tol && std::abs(a.back_w_mm - b.back_w_mm) <= tol &&
         (a.min_mm - b.min_mm).cwiseAbs().maxCoeff() <= tol && (a.step_mm - b.step_mm).cwiseAbs().maxCoeff() <= tol;
}

}  // namespace

std::filesystem::path TransgraphCache::defaultFolder() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return std::filesystem::path(xdg) / "fluoroct" / "transgraph";
  }
  if (const char* home = std::getenv("HOME"); home && *home) {
    return std::filesystem::path(home) / ".cache" / "fluoroct" / "transgraph";
  }
  std::error_code ec;
  return std::filesystem::temp_directory_path(ec) / "fluoroct-cache" / "transgraph";
}

std::uint64_t TransgraphCache::key(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                                   const TransgraphParameters& parameters) {
  Hash64 h;
  h.value(kVersion);
  h.value(ct.dims().x());
  h.value(ct.dims().y());
  h.value(ct.dims().z());
  h.matrix(ct.spacing_mm().data(), 3);
  h.matrix(ct.origin_lps_mm().data(), 3);
  h.matrix(ct.direction_lps().data(), 9);
  h.bytes(ct.voxels().data(), ct.voxels().size() * sizeof(float));
  const CameraIntrinsics& in = view.intrinsics();
  h.value(in.cols);
  h.value(in.rows);
  h.matrix(in.pixelSpacing_mm.data(), 2);
  h.value(in.sourceToDetector_mm);
  h.matrix(in.principalPoint_px.data(), 2);
  h.matrix(view.T_world_from_camera().matrix().data(), 16);
  h.matrix(T_world_from_ct.matrix().data(), 16);
  h.value(parameters.spacing_mm);
  h.value(parameters.offsetSpacing_mm);
  h.value(parameters.range.rotation_deg);
  h.value(parameters.range.translation_mm);
  h.value(parameters.planeMargin_mm);
  h.bytes(parameters.integratorId.data(), parameters.integratorId.size());
  return h.digest();
}

std::filesystem::path TransgraphCache::fileFor(const std::filesystem::path& folder, std::uint64_t key) {
  return folder / fmt::format("transgraph_{:016x}.fctg", key);
}

Status TransgraphCache::save(const std::filesystem::path& file, std::uint64_t key, const TransgraphLayout& layout,
                             const std::vector<float>& table) {
  if (table.size() != layout.rayCount()) {
    return fail(fmt::format("cannot cache a Transgraph whose table ({} values) does not match its layout ({} rays)",
                            table.size(), layout.rayCount()));
  }
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  if (ec) return fail(fmt::format("cannot create cache folder {}: {}", file.parent_path().string(), ec.message()));

  const std::vector<char> header = headerBytes(key, layout);
  Hash64 checksum;
  checksum.bytes(header.data(), header.size());
  checksum.bytes(table.data(), table.size() * sizeof(float));
  const std::uint64_t digest = checksum.digest();

  return AtomicFile::write(file, {AtomicFile::bytesOf(header.data(), header.size()),
                                  AtomicFile::bytesOf(table.data(), table.size()),
                                  AtomicFile::bytesOf(&digest, 1)});
}

Result<TransgraphCache::Entry> TransgraphCache::load(const std::filesystem::path& file, std::uint64_t key,
                                                     const TransgraphLayout& expectedLayout) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return fail(fmt::format("cannot open {}", file.string()));
  const std::streamoff fileSize = in.tellg();
  in.seekg(0);
  const std::size_t headerSize = headerBytes(0, TransgraphLayout{}).size();
  if (fileSize < static_cast<std::streamoff>(headerSize + sizeof(std::uint64_t))) {
    return fail(fmt::format("file is truncated: {} bytes, shorter than the {}-byte header", fileSize, headerSize));
  }
  std::vector<char> header(headerSize);
  in.read(header.data(), static_cast<std::streamsize>(headerSize));
  if (!in) return fail("cannot read the header");

  ByteReader r(header.data(), header.size());
  char magic[8];
  for (char& c : magic) r.get(c);
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) return fail("not a FluoroCT Transgraph cache file (bad magic)");
  std::uint32_t version = 0;
  std::uint64_t storedKey = 0, rays = 0;
  Entry entry;
  TransgraphLayout& layout = entry.layout;
  std::int32_t counts[4];
  r.get(version);
  r.get(storedKey);
  r.getDoubles(layout.origin_ct_mm.data(), 3);
  r.getDoubles(layout.R_ct_from_plane.data(), 9);
  r.get(layout.front_w_mm);
  r.get(layout.back_w_mm);
  r.getDoubles(layout.min_mm.data(), 4);
  r.getDoubles(layout.step_mm.data(), 4);
  for (std::int32_t& c : counts) r.get(c);
  if (!r.get(rays)) return fail("cannot read the header");
  if (version != kVersion) return fail(fmt::format("format version {} is not the supported {}", version, kVersion));
  if (storedKey != key) return fail(fmt::format("key {:016x} does not match the expected {:016x}", storedKey, key));
  for (int a = 0; a < 4; ++a) {
    if (counts[a] < 0) return fail("header holds a negative sample count");
    layout.counts[a] = counts[a];
  }
  if (rays != layout.rayCount()) return fail("header ray count disagrees with its sample counts");
  const std::uint64_t expectedSize = headerSize + rays * sizeof(float) + sizeof(std::uint64_t);
  if (static_cast<std::uint64_t>(fileSize) != expectedSize) {
    return fail(fmt::format("file size is {} bytes, but its header announces {} bytes (truncated or damaged)",
                            fileSize, expectedSize));
  }
  if (!sameLayout(layout, expectedLayout)) return fail("its table layout differs from the one planned now (stale)");

  entry.table.resize(rays);
  in.read(reinterpret_cast<char*>(entry.table.data()), static_cast<std::streamsize>(rays * sizeof(float)));
  std::uint64_t storedChecksum = 0;
  in.read(reinterpret_cast<char*>(&storedChecksum), sizeof(storedChecksum));
  if (!in) return fail("cannot read the table");
  Hash64 checksum;
  checksum.bytes(header.data(), header.size());
  checksum.bytes(entry.table.data(), entry.table.size() * sizeof(float));
  if (checksum.digest() != storedChecksum) return fail("checksum mismatch (the file is corrupt)");
  return entry;
}

Result<Transgraph> TransgraphCache::buildOrLoad(const Volume& ct, const Camera& view,
                                                const Eigen::Isometry3d& T_world_from_ct,
                                                const TransgraphParameters& parameters,
                                                Transgraph::RayIntegrator integrator,
                                                const std::filesystem::path& cacheFolder,
                                                const ProgressMonitor& monitor) {
  if (!integrator) return fail("Transgraph build needs a ray integrator, got none");
  auto planned = Transgraph::plan(ct, view, T_world_from_ct, parameters);
  if (!planned) return fail(planned.error());
  const std::filesystem::path folder = cacheFolder.empty() ? defaultFolder() : cacheFolder;
  const std::uint64_t cacheKey = key(ct, view, T_world_from_ct, parameters);
  const std::filesystem::path file = fileFor(folder, cacheKey);

  std::vector<std::string> warnings;
  std::error_code ec;
  if (std::filesystem::exists(file, ec)) {
    const auto start = std::chrono::steady_clock::now();
    auto entry = load(file, cacheKey, planned.value());
    std::string unusable = entry ? std::string() : entry.error();
    if (entry) {
      TransgraphBuildInfo info;
      info.loadedFromCache = true;
      info.cacheFile = file;
      info.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      auto loaded = Transgraph::fromTable(entry.value().layout, std::move(entry.value().table), integrator, info);
      if (loaded) return loaded;
      unusable = loaded.error();
    }
    warnings.push_back(fmt::format("Transgraph cache file {} is unusable ({}); rebuilt it", file.string(), unusable));
  }

  auto built = Transgraph::build(ct, view, T_world_from_ct, parameters, std::move(integrator), monitor);
  if (!built) return built;
  if (auto saved = save(file, cacheKey, built.value().layout(), built.value().table()); saved) {
    built.value().setCacheFile(file);
  } else {
    warnings.push_back(fmt::format("Transgraph not cached: {}", saved.error()));
  }
  for (auto& warning : warnings) built.addWarning(std::move(warning));
  return built;
}


}  // namespace fct
