#include <icd/mesh/core/primitives.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>

namespace icd {

TetMesh make_unit_tet() {
  TetMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.T.resize(1, 4);
  m.T << 0, 1, 2, 3;
  m.F = boundary_faces(m.T);
  return m;
}

TetMesh make_box_tet_mesh(const BoxMeshOptions& o) {
  if (o.nx < 1 || o.ny < 1 || o.nz < 1)
    throw ParameterError("make_box_tet_mesh: cell counts must be >= 1 (got " +
                         std::to_string(o.nx) + ", " + std::to_string(o.ny) + ", " +
                         std::to_string(o.nz) + ")");
  if (!(o.size.minCoeff() > 0.0) || !o.size.allFinite())
    throw ParameterError("make_box_tet_mesh: box size must be positive and finite");
  const int nx = o.nx, ny = o.ny, nz = o.nz;
  auto id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  TetMesh m;
  m.V.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        m.V.row(id(i, j, k)) =
            o.min_corner.transpose() +
            Eigen::RowVector3d(o.size.x() * i / nx, o.size.y() * j / ny, o.size.z() * k / nz);
  // Kuhn split: the 6 monotone paths from corner (0,0,0) to (1,1,1), one per
  // permutation of the axes; shared faces match between neighbouring cells.
  static constexpr std::array<std::array<int, 3>, 6> perms{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  m.T.resize(6 * nx * ny * nz, 4);
  int t = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : perms) {
          std::array<int, 3> c{i, j, k};
          std::array<int, 4> tet{};
          tet[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            tet[s + 1] = id(c[0], c[1], c[2]);
          }
          m.T.row(t++) << tet[0], tet[1], tet[2], tet[3];
        }
  // Make every tet positively oriented.
  const Eigen::VectorXd vol = signed_tet_volumes(m.V, m.T);
  for (int e = 0; e < m.T.rows(); ++e)
    if (vol[e] < 0) std::swap(m.T(e, 2), m.T(e, 3));
  m.F = boundary_faces(m.T);
  return m;
}

MatX3i boundary_faces(const Eigen::Ref<const MatX4i>& T) {
  // Local faces of a positively oriented tet (v0..v3), each outward.
  static constexpr int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  // Sort (sorted corner triple, 4 * tet + local face) records; a face whose
  // triple occurs once is on the boundary. O(#T log #T), no node allocations.
  struct Record {
    std::array<int, 3> key;
    int64_t slot;
  };
  const int64_t n = 4 * static_cast<int64_t>(T.rows());
  std::vector<Record> records(static_cast<size_t>(n));
  for (Eigen::Index e = 0; e < T.rows(); ++e)
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> key{T(e, faces[f][0]), T(e, faces[f][1]), T(e, faces[f][2])};
      std::sort(key.begin(), key.end());
      records[4 * e + f] = {key, 4 * e + f};
    }
  std::sort(records.begin(), records.end(),
            [](const Record& a, const Record& b) { return a.key < b.key; });
  std::vector<char> on_boundary(static_cast<size_t>(n), 0);
  for (size_t i = 0; i < records.size();) {
    size_t j = i + 1;
    while (j < records.size() && records[j].key == records[i].key) ++j;
    if (j == i + 1) on_boundary[records[i].slot] = 1;
    i = j;
  }
  MatX3i F(std::count(on_boundary.begin(), on_boundary.end(), 1), 3);
  Eigen::Index row = 0;
  for (int64_t slot = 0; slot < n; ++slot)
    if (on_boundary[slot]) {
      const Eigen::Index e = slot / 4;
      const int* f = faces[slot % 4];
      F.row(row++) << T(e, f[0]), T(e, f[1]), T(e, f[2]);
    }
  return F;
}

Eigen::VectorXi boundary_nodes(const Eigen::Ref<const MatX3i>& F) {
  std::vector<int> ids(F.data(), F.data() + F.size());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return Eigen::Map<const Eigen::VectorXi>(ids.data(), static_cast<Eigen::Index>(ids.size()));
}

Eigen::VectorXd signed_tet_volumes(const Eigen::Ref<const MatX3d>& V,
                                   const Eigen::Ref<const MatX4i>& T) {
  Eigen::VectorXd vol(T.rows());
  for (int e = 0; e < T.rows(); ++e) {
    Eigen::Matrix3d D;
    for (int c = 0; c < 3; ++c) D.col(c) = (V.row(T(e, c + 1)) - V.row(T(e, 0))).transpose();
    vol[e] = D.determinant() / 6.0;
  }
  return vol;
}

SurfaceMesh make_icosphere(int subdivisions, double radius) {
  if (subdivisions < 0 || subdivisions > 8)
    throw ParameterError("make_icosphere: subdivisions must be in [0, 8]");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int idx = static_cast<int>(v.size()) - 1;
      mid.emplace(key, idx);
      return idx;
    };
    std::vector<std::array<int, 3>> nf;
    nf.reserve(f.size() * 4);
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                c = midpoint(tri[2], tri[0]);
      nf.push_back({tri[0], a, c});
      nf.push_back({tri[1], b, a});
      nf.push_back({tri[2], c, b});
      nf.push_back({a, b, c});
    }
    f.swap(nf);
  }
  SurfaceMesh m;
  m.V.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (size_t i = 0; i < v.size(); ++i) m.V.row(i) = radius * v[i].transpose();
  m.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row(i) << f[i][0], f[i][1], f[i][2];
  return m;
}

SurfaceMesh make_box_surface(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  SurfaceMesh m;
  m.V.resize(8, 3);
  for (int c = 0; c < 8; ++c)
    m.V.row(c) << ((c & 1) ? hi.x() : lo.x()), ((c & 2) ? hi.y() : lo.y()),
        ((c & 4) ? hi.z() : lo.z());
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3,  // z = lo
      4, 5, 6, 5, 7, 6,     // z = hi
      0, 1, 4, 1, 5, 4,     // y = lo
      2, 6, 3, 3, 6, 7,     // y = hi
      0, 4, 2, 2, 4, 6,     // x = lo
      1, 3, 5, 3, 7, 5;     // x = hi
  return m;
}

SurfaceMesh make_torus(double R, double r, int nu, int nv) {
  if (!(R > r && r > 0) || nu < 3 || nv < 3)
    throw ParameterError("make_torus: need R > r > 0 and nu, nv >= 3");
  SurfaceMesh m;
  m.V.resize(nu * nv, 3);
  m.F.resize(2 * nu * nv, 3);
  const double two_pi = 2.0 * std::numbers::pi;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = two_pi * i / nu, w = two_pi * j / nv;
      m.V.row(i * nv + j) << (R + r * std::cos(w)) * std::cos(u),
          (R + r * std::cos(w)) * std::sin(u), r * std::sin(w);
    }
  int f = 0;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const int a = i * nv + j, b = ((i + 1) % nu) * nv + j, c = ((i + 1) % nu) * nv + (j + 1) % nv,
                d = i * nv + (j + 1) % nv;
      m.F.row(f++) << a, b, c;
      m.F.row(f++) << a, c, d;
    }
  return m;
}

}  // namespace icd
