#include <icd/mesh/io/surface_reader.hpp>

#include <algorithm>
#include <cctype>
#include <string>

#include <icd/mesh/io/detail/file_bytes.hpp>
#include <icd/mesh/io/detail/input_error.hpp>

namespace icd {

SurfaceMesh read_surface_mesh(const std::filesystem::path& path, ReadReport* report) {
  const std::string name = path.string();
  detail::check_regular_file(path, file_limits::kSurfaceMesh, "mesh");
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  using Parser = SurfaceMesh (*)(std::string_view, std::string_view, ReadReport*);
  Parser parser = nullptr;
  if (ext == ".off")
    parser = &parse_off;
  else if (ext == ".obj")
    parser = &parse_obj;
  else if (ext == ".ply")
    parser = &parse_ply;
  else if (ext == ".stl")
    parser = &parse_stl;
  else
    detail::throw_input_error(
        name, "unknown mesh file extension '" + ext + "' (supported: .off, .obj, .ply, .stl)");
  const std::string bytes = detail::read_file_bytes(path, file_limits::kSurfaceMesh, "mesh");
  return parser(bytes, name, report);
}

}  // namespace icd
