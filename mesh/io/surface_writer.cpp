#include <icd/mesh/io/surface_writer.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include <icd/mesh/io/atomic_write.hpp>
#include <icd/mesh/io/detail/number_format.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd {
namespace {

void check_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh) {
  const std::string where = path.string() + ": cannot write mesh: ";
  if (!mesh.V.allFinite()) throw ParameterError(where + "V has a non-finite coordinate");
  if (mesh.F.size() > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.V.rows()))
    throw ParameterError(where + "F has an index outside [0, " + std::to_string(mesh.V.rows()) +
                         ")");
}

void append_vertex(std::string& out, const SurfaceMesh& mesh, Eigen::Index i) {
  for (int c = 0; c < 3; ++c) {
    if (c) out += ' ';
    detail::append_number(out, mesh.V(i, c));
  }
  out += '\n';
}

}  // namespace

void write_off(const std::filesystem::path& path, const SurfaceMesh& mesh) {
  check_mesh(path, mesh);
  std::string out =
      "OFF\n" + std::to_string(mesh.V.rows()) + ' ' + std::to_string(mesh.F.rows()) + " 0\n";
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) append_vertex(out, mesh, i);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += '3';
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      detail::append_number(out, static_cast<int64_t>(mesh.F(f, c)));
    }
    out += '\n';
  }
  write_file_atomically(path, out);
}

void write_obj(const std::filesystem::path& path, const SurfaceMesh& mesh) {
  check_mesh(path, mesh);
  std::string out = "# icd surface mesh\n";
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    out += "v ";
    append_vertex(out, mesh, i);
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += 'f';
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      detail::append_number(out, static_cast<int64_t>(mesh.F(f, c)) + 1);
    }
    out += '\n';
  }
  write_file_atomically(path, out);
}

void write_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".off") return write_off(path, mesh);
  if (ext == ".obj") return write_obj(path, mesh);
  throw ParameterError(path.string() + ": cannot write mesh: unknown extension '" + ext +
                       "' (supported: .off, .obj)");
}

}  // namespace icd
