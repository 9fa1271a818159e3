// icd-meshinfo: reads surface meshes (OFF, OBJ, PLY, STL) or our VTU files
// (tet mesh: statistics of its boundary; triangles; sphere set) and prints
// their statistics. Usage: icd-meshinfo FILE... (--help); exit status 1 if any file failed.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include <icd/mesh/core/mesh_stats.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/vtu_reader.hpp>

namespace {

void row(const char* key, const std::string& value) {
  std::printf("  %-24s %s\n", key, value.c_str());
}

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

void print_stats(const std::string& file, const icd::ReadReport& report, double read_ms,
                 const icd::SurfaceStats& s) {
  std::printf("%s\n", file.c_str());
  row("format", report.format);
  row("read time (ms)", num(read_ms));
  row("vertices", std::to_string(s.vertices));
  row("faces", std::to_string(s.faces));
  row("edges", std::to_string(s.edges));
  row("bounding box min",
      num(s.bbox_min.x()) + " " + num(s.bbox_min.y()) + " " + num(s.bbox_min.z()));
  row("bounding box max",
      num(s.bbox_max.x()) + " " + num(s.bbox_max.y()) + " " + num(s.bbox_max.z()));
  row("surface area", num(s.area));
  row("enclosed volume", num(s.volume) + (s.boundary_edges > 0 ? " (surface is open)" : ""));
  row("boundary edges", std::to_string(s.boundary_edges));
  row("non-manifold edges", std::to_string(s.nonmanifold_edges));
  row("inconsistent edges", std::to_string(s.inconsistent_edges));
  row("duplicate vertices", std::to_string(s.duplicate_vertices));
  row("unreferenced vertices", std::to_string(s.unreferenced_vertices));
  row("degenerate faces", std::to_string(s.degenerate_faces));
  row("components", std::to_string(s.components));
  row("Euler characteristic", std::to_string(s.euler_characteristic));
  for (const std::string& note : report.notes) row("note", note);
  for (const std::string& warning : report.warnings) row("warning", warning);
}

// A VTU file: its cells decide what it holds.
void print_vtu(const std::string& file) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<uint8_t> types;
  std::vector<std::string> point_data;  // (not the whole VtuData: the file is read again below)
  {
    icd::VtuData d = icd::read_vtu(file);
    types = std::move(d.types);
    for (const auto& a : d.point_data)
      point_data.push_back(a.name + " (" + std::to_string(a.values.cols()) + " components)");
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const auto all = [&](int type) {
    return !types.empty() &&
           std::all_of(types.begin(), types.end(), [&](uint8_t t) { return t == type; });
  };
  icd::ReadReport report;
  report.format = "VTU";
  if (all(10)) {
    const icd::TetMesh tets = icd::read_vtu_tet_mesh(file);
    const Eigen::VectorXd vol = icd::signed_tet_volumes(tets.V, tets.T);
    report.format = "VTU tetrahedra (statistics of the boundary surface)";
    print_stats(file, report, ms, icd::compute_surface_stats({tets.V, tets.F}));
    row("tets", std::to_string(tets.T.rows()));
    row("tet volume sum", num(vol.sum()));
    row("smallest tet volume", num(vol.minCoeff()));
  } else if (all(5)) {
    report.format = "VTU triangles";
    print_stats(file, report, ms, icd::compute_surface_stats(icd::read_vtu_surface_mesh(file)));
  } else if (all(1)) {
    const icd::SphereSet s = icd::read_vtu_sphere_set(file);
    std::printf("%s\n", file.c_str());
    row("format", "VTU sphere set");
    row("spheres", std::to_string(s.radii.size()));
    row("radius min / max", num(s.radii.minCoeff()) + " / " + num(s.radii.maxCoeff()));
  } else {
    throw icd::InputError(file + ": cells are not all tetrahedra, triangles or vertices");
  }
  for (const std::string& a : point_data) row("point data", a);
}

// Reports each file that fails ("icd-meshinfo: <what>") and goes on to the
// next; status 1 if any failed.
int run(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  icd::experiments::Cli cli(
      "icd-meshinfo",
      "  Reads triangle surface meshes (.off .obj .ply .stl) or VTU files written by icd\n"
      "  (.vtu: tetrahedra, triangles or sphere sets) and prints their statistics; exit\n"
      "  status 1 if any file failed.");
  cli.arguments("FILE", files, "mesh or VTU files", true);
  if (const auto status = cli.parse(argc, argv)) return *status;
  int status = 0;
  for (const std::filesystem::path& file : files) {
    const std::string name = file.string();
    try {
      std::string ext = file.extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (ext == ".vtu") {
        print_vtu(name);
        continue;
      }
      icd::ReadReport report;
      const auto t0 = std::chrono::steady_clock::now();
      const icd::SurfaceMesh mesh = icd::read_surface_mesh(name, &report);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      print_stats(name, report, ms, icd::compute_surface_stats(mesh));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "icd-meshinfo: %s\n", e.what());
      status = 1;
    }
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("icd-meshinfo", run, argc, argv);
}
