#include <icd/coupling/asset_bundle.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include <icd/mesh/io/vtk_writer.hpp>
#include <icd/mesh/io/vtu_reader.hpp>

namespace icd::coupling {

static_assert(std::endian::native == std::endian::little,
              "bundle.icdb is little-endian; a big-endian port needs byte swapping here");

namespace {

constexpr char kMagic[8] = {'I', 'C', 'D', 'A', 'S', 'S', 'E', 'T'};
constexpr uint32_t kInt32 = 1, kFloat64 = 2;
constexpr std::size_t kHeaderBytes = 32, kSectionHeaderBytes = 32;

// Layout of the "meta" section.
enum Meta : int {
  kDenseV,
  kDenseF,
  kCoarseV,
  kCoarseT,
  kSurfaceNodes,
  kLinks,
  kLinkCoarseNodes,
  kSphereNodes,
  kLevelOffsets,
  kAssoc,
  kMetaSize
};

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
T get(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

class Writer {
 public:
  template <class T>
  void section(const char* name, const T* data, std::size_t count) {
    static_assert(std::is_same_v<T, int32_t> || std::is_same_v<T, double>);
    char padded[8] = {};
    std::memcpy(padded, name, std::min<std::size_t>(std::strlen(name), 8));
    m_body.append(padded, 8);
    put(m_body, std::is_same_v<T, int32_t> ? kInt32 : kFloat64);
    put(m_body, uint32_t{0});
    put(m_body, static_cast<uint64_t>(count));
    put(m_body, fnv1a64(data, count * sizeof(T)));
    m_body.append(reinterpret_cast<const char*>(data), count * sizeof(T));
    ++m_sections;
  }
  template <class T>
  void section(const char* name, const std::vector<T>& v) {
    section(name, v.data(), v.size());
  }
  std::string finish() const {
    std::string out;
    out.append(kMagic, 8);
    put(out, kBundleFormatVersion);
    put(out, m_sections);
    put(out, static_cast<uint64_t>(kHeaderBytes + m_body.size()));
    put(out, fnv1a64(out.data(), out.size()));
    return out + m_body;
  }

 private:
  std::string m_body;
  uint32_t m_sections = 0;
};

struct Section {
  uint32_t type = 0;
  uint64_t count = 0;
  const char* data = nullptr;
};

class Reader {
 public:
  Reader(std::string bytes, std::string file) : m_bytes(std::move(bytes)), m_file(std::move(file)) {
    if (m_bytes.size() < kHeaderBytes || std::memcmp(m_bytes.data(), kMagic, 8) != 0) {
      if (m_bytes.size() >= 8 && std::memcmp(m_bytes.data(), kMagic, 8) == 0)
        fail("truncated: " + std::to_string(m_bytes.size()) + " bytes, the header alone has 32");
      fail("not an icd asset bundle (bad magic)");
    }
    const char* h = m_bytes.data();
    if (get<uint64_t>(h + 24) != fnv1a64(h, 24))
      fail("header checksum mismatch: the file is corrupted");
    const auto version = get<uint32_t>(h + 8);
    if (version != kBundleFormatVersion)
      fail("format version " + std::to_string(version) +
           " is not supported (this build reads version " + std::to_string(kBundleFormatVersion) +
           "); re-run icd-preprocess");
    const auto sections = get<uint32_t>(h + 12);
    const auto total = get<uint64_t>(h + 16);
    if (total != m_bytes.size())
      fail(std::string(total > m_bytes.size() ? "truncated" : "trailing data") +
           ": the header announces " + std::to_string(total) + " bytes, the file has " +
           std::to_string(m_bytes.size()));
    std::size_t pos = kHeaderBytes;
    for (uint32_t s = 0; s < sections; ++s) {
      if (m_bytes.size() - pos < kSectionHeaderBytes)
        fail("truncated in the header of section " + std::to_string(s));
      const char* p = m_bytes.data() + pos;
      const std::string name(p, strnlen(p, 8));
      Section sec;
      sec.type = get<uint32_t>(p + 8);
      sec.count = get<uint64_t>(p + 16);
      const auto checksum = get<uint64_t>(p + 24);
      for (std::size_t c = name.size(); c < 8; ++c)
        if (p[c] != 0)
          fail("section " + std::to_string(s) + " has a malformed name: the file is corrupted");
      if (get<uint32_t>(p + 12) != 0)
        fail("section '" + name + "' has a non-zero reserved field: the file is corrupted");
      if (sec.type != kInt32 && sec.type != kFloat64)
        fail("section '" + name + "' has unknown element type " + std::to_string(sec.type));
      const uint64_t elem = sec.type == kInt32 ? 4 : 8;
      pos += kSectionHeaderBytes;
      if (sec.count > (m_bytes.size() - pos) / elem)
        fail("truncated: section '" + name + "' announces " + std::to_string(sec.count * elem) +
             " bytes at offset " + std::to_string(pos) + ", only " +
             std::to_string(m_bytes.size() - pos) + " remain");
      sec.data = m_bytes.data() + pos;
      if (fnv1a64(sec.data, sec.count * elem) != checksum)
        fail("section '" + name + "' checksum mismatch: the file is corrupted");
      pos += sec.count * elem;
      if (!m_sections.emplace(name, sec).second) fail("section '" + name + "' appears twice");
    }
    if (pos != m_bytes.size()) fail("trailing bytes after the last section");
  }

  /// Copies section `name` (of type T and exactly `count` elements) into out.
  template <class T>
  void read(const char* name, uint64_t count, T* out) const {
    const Section& s = check<T>(name, count);
    if (count) std::memcpy(out, s.data, count * sizeof(T));
  }
  template <class T>
  std::vector<T> read(const char* name, uint64_t count) const {
    check<T>(name, count);  // before allocating: counts come from the file
    std::vector<T> v(count);
    read(name, count, v.data());
    return v;
  }
  /// The section `name`, after checking that it has type T and `count` elements.
  template <class T>
  const Section& check(const char* name, uint64_t count) const {
    const auto it = m_sections.find(name);
    if (it == m_sections.end()) fail(std::string("section '") + name + "' is missing");
    const Section& s = it->second;
    if (s.type != (std::is_same_v<T, int32_t> ? kInt32 : kFloat64))
      fail(std::string("section '") + name + "' has the wrong element type");
    if (s.count != count)
      fail(std::string("section '") + name + "' has " + std::to_string(s.count) +
           " elements, expected " + std::to_string(count));
    return s;
  }
  uint64_t count(const char* name) const {
    const auto it = m_sections.find(name);
    if (it == m_sections.end()) fail(std::string("section '") + name + "' is missing");
    return it->second.count;
  }

  [[noreturn]] void fail(const std::string& msg) const { throw InputError(m_file + ": " + msg); }

 private:
  std::string m_bytes;
  std::string m_file;
  std::map<std::string, Section> m_sections;
};

std::array<int32_t, 8> fingerprints(const SurfaceMesh& dense, const TetMesh& coarse) {
  const uint64_t h[4] = {fnv1a64(dense.V.data(), sizeof(double) * dense.V.size()),
                         fnv1a64(dense.F.data(), sizeof(int) * dense.F.size()),
                         fnv1a64(coarse.V.data(), sizeof(double) * coarse.V.size()),
                         fnv1a64(coarse.T.data(), sizeof(int) * coarse.T.size())};
  std::array<int32_t, 8> out{};
  for (int i = 0; i < 4; ++i) {
    out[2 * i] = static_cast<int32_t>(static_cast<uint32_t>(h[i] & 0xffffffffu));
    out[2 * i + 1] = static_cast<int32_t>(static_cast<uint32_t>(h[i] >> 32));
  }
  return out;
}

std::vector<double> flatten(const std::vector<collision::Sphere>& s) {
  std::vector<double> out;
  out.reserve(4 * s.size());
  for (const auto& x : s) out.insert(out.end(), {x.x, x.y, x.z, x.r});
  return out;
}

std::vector<collision::Sphere> unflatten(const std::vector<double>& v) {
  std::vector<collision::Sphere> out(v.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = {v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]};
  return out;
}

std::string read_file(const std::filesystem::path& path) {
  return read_input_file(path, file_limits::kBundle, "asset bundle file");
}

void check_consistent(const AssetBundle& b) {
  const auto fail = [](const std::string& m) { throw ParameterError("write_asset_bundle: " + m); };
  const auto M = b.coarse.V.rows();
  if (b.links.num_links() != b.dense.V.rows())
    fail(std::to_string(b.links.num_links()) + " links for " + std::to_string(b.dense.V.rows()) +
         " dense vertices");
  if (b.links.num_coarse_nodes != M) fail("links refer to a coarse mesh of another size");
  for (Eigen::Index i = 0; i < b.surface_nodes.size(); ++i)
    if (b.surface_nodes[i] < 0 || b.surface_nodes[i] >= M) fail("surface node index out of range");
  try {
    validate(b.links, "write_asset_bundle");
    if (b.spheres.num_nodes() > 0) collision::validate(b.spheres);
  } catch (const InputError& e) {
    fail(e.what());
  }
}

}  // namespace

uint64_t fnv1a64(const void* data, std::size_t size) {
  uint64_t h = 14695981039346656037ull;
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

void write_asset_bundle(const std::filesystem::path& folder, const AssetBundle& b) {
  check_consistent(b);
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw InputError(folder.string() + ": cannot create the bundle folder: " + ec.message());
  write_vtu_surface_mesh(folder / kDenseSurfaceFile, b.dense);
  write_vtu_tet_mesh(folder / kCoarseTetsFile, b.coarse);

  const collision::SphereTree& t = b.spheres;
  std::array<int32_t, kMetaSize> meta{};
  meta[kDenseV] = static_cast<int32_t>(b.dense.V.rows());
  meta[kDenseF] = static_cast<int32_t>(b.dense.F.rows());
  meta[kCoarseV] = static_cast<int32_t>(b.coarse.V.rows());
  meta[kCoarseT] = static_cast<int32_t>(b.coarse.T.rows());
  meta[kSurfaceNodes] = static_cast<int32_t>(b.surface_nodes.size());
  meta[kLinks] = b.links.num_links();
  meta[kLinkCoarseNodes] = b.links.num_coarse_nodes;
  meta[kSphereNodes] = t.num_nodes();
  meta[kLevelOffsets] = static_cast<int32_t>(t.level_offset.size());
  meta[kAssoc] = static_cast<int32_t>(t.assoc_nodes.size());
  const auto fp = fingerprints(b.dense, b.coarse);
  const std::vector<int32_t> surf(b.surface_nodes.data(),
                                  b.surface_nodes.data() + b.surface_nodes.size());

  Writer w;
  w.section("meta", meta.data(), meta.size());
  w.section("fprint", fp.data(), fp.size());
  w.section("surfnode", surf);
  w.section("lnk_node", b.links.nodes.data(), static_cast<std::size_t>(b.links.nodes.size()));
  w.section("lnk_alph", b.links.alpha.data(), static_cast<std::size_t>(b.links.alpha.size()));
  w.section("lnk_coef", b.links.coeffs.data(), static_cast<std::size_t>(b.links.coeffs.size()));
  w.section("sph_cur", flatten(t.spheres));
  w.section("sph_rest", flatten(t.rest_spheres));
  w.section("sph_fch", t.first_child);
  w.section("sph_cnt", t.child_count);
  w.section("sph_lvl", t.level);
  w.section("sph_loff", t.level_offset);
  w.section("asc_off", t.assoc_offset);
  w.section("asc_node", t.assoc_nodes);
  w.section("asc_dist", t.assoc_rest_dist);
  write_file_atomically(folder / kBundleDataFile, w.finish());
}

AssetBundle read_asset_bundle(const std::filesystem::path& folder) {
  const std::filesystem::path data_path = folder / kBundleDataFile;
  const Reader r(read_file(data_path), data_path.string());
  std::array<int32_t, kMetaSize> meta{};
  r.read("meta", kMetaSize, meta.data());
  for (int i = 0; i < kMetaSize; ++i)
    if (meta[i] < 0) r.fail("negative count in section 'meta'");
  std::array<int32_t, 8> fp{};
  r.read("fprint", fp.size(), fp.data());

  AssetBundle b;
  b.dense = read_vtu_surface_mesh(folder / kDenseSurfaceFile);
  b.coarse = read_vtu_tet_mesh(folder / kCoarseTetsFile);
  if (b.dense.V.rows() != meta[kDenseV] || b.dense.F.rows() != meta[kDenseF] ||
      b.coarse.V.rows() != meta[kCoarseV] || b.coarse.T.rows() != meta[kCoarseT] ||
      fingerprints(b.dense, b.coarse) != fp) {
    std::ostringstream s;
    s << "the meshes in " << folder.string() << " do not match " << kBundleDataFile << " (recorded "
      << meta[kDenseV] << "/" << meta[kDenseF] << " dense vertices/faces and " << meta[kCoarseV]
      << "/" << meta[kCoarseT] << " coarse vertices/tets, found " << b.dense.V.rows() << "/"
      << b.dense.F.rows() << " and " << b.coarse.V.rows() << "/" << b.coarse.T.rows()
      << ", or different coordinates): files from different preprocessing runs?";
    r.fail(s.str());
  }
  const auto surf = r.read<int32_t>("surfnode", static_cast<uint64_t>(meta[kSurfaceNodes]));
  b.surface_nodes.resize(static_cast<Eigen::Index>(surf.size()));
  for (std::size_t i = 0; i < surf.size(); ++i) {
    if (surf[i] < 0 || surf[i] >= meta[kCoarseV])
      r.fail("surface node " + std::to_string(i) + " out of range");
    b.surface_nodes[static_cast<Eigen::Index>(i)] = surf[i];
  }
  const int N = meta[kLinks];
  if (N != meta[kDenseV])
    r.fail("has " + std::to_string(N) + " links for " + std::to_string(meta[kDenseV]) +
           " dense vertices");
  if (meta[kLinkCoarseNodes] != meta[kCoarseV])
    r.fail("links refer to a coarse mesh of another size");
  r.check<int32_t>("lnk_node", 3ull * N);  // before allocating
  b.links.nodes.resize(N, 3);
  b.links.alpha.resize(N, 3);
  b.links.coeffs.resize(N, 3);
  b.links.num_coarse_nodes = meta[kLinkCoarseNodes];
  r.read("lnk_node", 3ull * N, b.links.nodes.data());
  r.read("lnk_alph", 3ull * N, b.links.alpha.data());
  r.read("lnk_coef", 3ull * N, b.links.coeffs.data());
  validate(b.links, data_path.string().c_str());

  const uint64_t S = static_cast<uint64_t>(meta[kSphereNodes]);
  collision::SphereTree& t = b.spheres;
  t.spheres = unflatten(r.read<double>("sph_cur", 4 * S));
  t.rest_spheres = unflatten(r.read<double>("sph_rest", 4 * S));
  t.first_child = r.read<int32_t>("sph_fch", S);
  t.child_count = r.read<int32_t>("sph_cnt", S);
  t.level = r.read<int32_t>("sph_lvl", S);
  t.level_offset = r.read<int32_t>("sph_loff", static_cast<uint64_t>(meta[kLevelOffsets]));
  t.assoc_offset = r.read<int32_t>("asc_off", r.count("asc_off"));
  t.assoc_nodes = r.read<int32_t>("asc_node", static_cast<uint64_t>(meta[kAssoc]));
  t.assoc_rest_dist = r.read<double>("asc_dist", static_cast<uint64_t>(meta[kAssoc]));
  if (S > 0) {
    try {
      collision::validate(t);
    } catch (const InputError& e) {
      r.fail(std::string("invalid sphere tree: ") + e.what());
    }
    for (int32_t v : t.assoc_nodes)
      if (v < 0 || v >= meta[kCoarseV])
        r.fail("sphere association refers to coarse node " + std::to_string(v));
  }
  return b;
}

}  // namespace icd::coupling
