// icd-meshinfo: reads surface meshes (OFF, OBJ, PLY, STL) and prints their
// statistics. Usage: icd-meshinfo FILE... ; exit status 1 if any file failed.
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "mesh/io/mesh_stats.hpp"
#include "mesh/io/surface_reader.hpp"

namespace {

void print_stats(const std::string& file, const icd::ReadReport& report, double read_ms,
                 const icd::SurfaceStats& s) {
  const auto row = [](const char* key, const std::string& value) {
    std::printf("  %-24s %s\n", key, value.c_str());
  };
  const auto num = [](double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return std::string(buf);
  };
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
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::fprintf(
        stderr,
        "usage: %s FILE...\n"
        "Reads triangle surface meshes (.off .obj .ply .stl) and prints their statistics.\n",
        argv[0]);
    return argc < 2 ? 2 : 0;
  }
  int status = 0;
  for (int i = 1; i < argc; ++i) {
    try {
      icd::ReadReport report;
      const auto t0 = std::chrono::steady_clock::now();
      const icd::SurfaceMesh mesh = icd::read_surface_mesh(argv[i], &report);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      print_stats(argv[i], report, ms, icd::compute_surface_stats(mesh));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "icd-meshinfo: %s\n", e.what());
      status = 1;
    }
  }
  return status;
}
