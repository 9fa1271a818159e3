// fuzz_mesh_readers: mutation fuzzing of the mesh parsers (OFF, OBJ, PLY
// ascii/binary, STL ascii/binary, VTU). Each mutant must either parse into a
// valid mesh or throw icd::InputError whose message starts with the source
// name; anything else (another exception, a crash, a sanitizer report when
// built with ICD_SANITIZE=ON) is a bug.
// Usage: fuzz_mesh_readers [ITERATIONS=200000] [SEED=0] (--help)
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>
#include <icd/mesh/io/surface_writer.hpp>
#include <icd/mesh/io/vtk_writer.hpp>
#include <icd/mesh/io/vtu_reader.hpp>

namespace {

struct Seed {
  std::string name;  // also the source name passed to the parser
  std::string bytes;
  std::function<void(std::string_view, std::string_view)> parse;  // throws or validates
};

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void check_surface(const icd::SurfaceMesh& m) {
  if (m.V.rows() < 1 || m.F.rows() < 1 || !m.V.allFinite() || m.F.minCoeff() < 0 ||
      m.F.maxCoeff() >= m.V.rows()) {
    std::fprintf(stderr, "BUG: a parser returned an invalid mesh\n");
    std::abort();
  }
}

template <class T>
void put(std::string& s, T v, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big != (std::endian::native == std::endian::big))
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  s.append(b, sizeof(T));
}

std::vector<Seed> make_seeds() {
  const icd::SurfaceMesh m = icd::make_icosphere(0);
  const auto tmp = std::filesystem::temp_directory_path() / "icd_fuzz_seed";
  std::vector<Seed> seeds;
  const auto surface = [](auto parser) {
    return
        [parser](std::string_view b, std::string_view n) { check_surface(parser(b, n, nullptr)); };
  };
  icd::write_off(tmp.string() + ".off", m);
  seeds.push_back({"seed.off", slurp(tmp.string() + ".off"), surface(&icd::parse_off)});
  icd::write_obj(tmp.string() + ".obj", m);
  seeds.push_back({"seed.obj", slurp(tmp.string() + ".obj"), surface(&icd::parse_obj)});
  for (int format = 0; format < 3; ++format) {
    const bool big = format == 2;
    std::string s = std::string("ply\nformat ") +
                    (format == 0 ? "ascii"
                     : big       ? "binary_big_endian"
                                 : "binary_little_endian") +
                    " 1.0\nelement vertex " + std::to_string(m.V.rows()) +
                    "\nproperty double x\nproperty float y\nproperty double z\nelement face " +
                    std::to_string(m.F.rows()) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < m.V.rows(); ++i) {
      if (format == 0) {
        s += std::to_string(m.V(i, 0)) + " " + std::to_string(m.V(i, 1)) + " " +
             std::to_string(m.V(i, 2)) + "\n";
      } else {
        put<double>(s, m.V(i, 0), big);
        put<float>(s, static_cast<float>(m.V(i, 1)), big);
        put<double>(s, m.V(i, 2), big);
      }
    }
    for (int f = 0; f < m.F.rows(); ++f) {
      if (format == 0) {
        s += "3 " + std::to_string(m.F(f, 0)) + " " + std::to_string(m.F(f, 1)) + " " +
             std::to_string(m.F(f, 2)) + "\n";
      } else {
        put<uint8_t>(s, 3, big);
        for (int c = 0; c < 3; ++c) put<int32_t>(s, m.F(f, c), big);
      }
    }
    seeds.push_back({"seed.ply", s, surface(&icd::parse_ply)});
  }
  std::string ascii = "solid s\n", binary(80, ' ');
  put<uint32_t>(binary, static_cast<uint32_t>(m.F.rows()), false);
  for (int f = 0; f < m.F.rows(); ++f) {
    ascii += "facet normal 0 0 1\nouter loop\n";
    for (int c = 0; c < 3; ++c) put<float>(binary, 0.0f, false);
    for (int k = 0; k < 3; ++k) {
      ascii += "vertex " + std::to_string(m.V(m.F(f, k), 0)) + " " +
               std::to_string(m.V(m.F(f, k), 1)) + " " + std::to_string(m.V(m.F(f, k), 2)) + "\n";
      for (int c = 0; c < 3; ++c) put<float>(binary, static_cast<float>(m.V(m.F(f, k), c)), false);
    }
    ascii += "endloop\nendfacet\n";
    put<uint16_t>(binary, 0, false);
  }
  ascii += "endsolid s\n";
  seeds.push_back({"seed.stl", ascii, surface(&icd::parse_stl)});
  seeds.push_back({"seed.stl", binary, surface(&icd::parse_stl)});
  icd::write_vtu_surface_mesh(tmp.string() + ".vtu", m);
  seeds.push_back(
      {"seed.vtu", slurp(tmp.string() + ".vtu"), [](std::string_view b, std::string_view n) {
         const icd::VtuData d = icd::parse_vtu(b, n);
         if (!d.points.allFinite() || d.offsets.size() != d.types.size()) std::abort();
       }});
  for (const char* ext : {".off", ".obj", ".vtu"}) std::filesystem::remove(tmp.string() + ext);
  return seeds;
}

std::string mutate(const std::string& seed, std::mt19937_64& rng) {
  std::string s = seed;
  const auto pick = [&](size_t n) { return n == 0 ? 0 : static_cast<size_t>(rng() % n); };
  static const char* const tokens[] = {
      " ",    "\n",          "-1",         "0",          "nan",
      "inf",  "1e999",       "4294967295", "2147483648", "99999999999999999999",
      "<",    ">",           "\"",         "/",          "#",
      "\r\n", "end_header\n"};
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    switch (rng() % 6) {
      case 0:  // random byte
        if (!s.empty()) s[pick(s.size())] = static_cast<char>(rng());
        break;
      case 1:  // truncate
        s.resize(pick(s.size() + 1));
        break;
      case 2:  // delete a range
        if (!s.empty()) {
          const size_t p = pick(s.size());
          s.erase(p, 1 + pick(16));
        }
        break;
      case 3:  // duplicate a range
        if (!s.empty()) {
          const size_t p = pick(s.size());
          s.insert(pick(s.size()), s.substr(p, 1 + pick(64)));
        }
        break;
      case 4:  // insert an interesting token
        s.insert(pick(s.size() + 1), tokens[pick(std::size(tokens))]);
        break;
      default:  // overwrite 4 bytes with an extreme little-endian integer
        if (s.size() >= 4) {
          const uint32_t v = (rng() & 1) ? 0xffffffffu : 0x7fffffffu;
          const size_t p = pick(s.size() - 3);
          for (int b = 0; b < 4; ++b) s[p + b] = static_cast<char>((v >> (8 * b)) & 0xff);
        }
    }
  }
  return s;
}

int run(int argc, char** argv) {
  long iterations = 200000;
  unsigned long seed = 0;
  using icd::experiments::Cli;
  Cli cli("fuzz_mesh_readers",
          "  Mutation fuzzing of every mesh reader: each mutant parses or is refused with an\n"
          "  InputError naming its source; anything else is reported as BUG (exit status 1).");
  cli.argument("ITERATIONS", "mutants to try (default 200000)", false,
               [&](const std::string& v) { iterations = Cli::parse_integer<long>(v, 0); })
      .argument("SEED", "random seed (default 0)", false,
                [&](const std::string& v) { seed = Cli::parse_integer<unsigned long>(v); });
  if (const auto status = cli.parse(argc, argv)) return *status;
  const std::vector<Seed> seeds = make_seeds();
  std::mt19937_64 rng(seed);
  long accepted = 0, rejected = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (long it = 0; it < iterations; ++it) {
    const Seed& s = seeds[it % seeds.size()];
    const std::string bytes = mutate(s.bytes, rng);
    try {
      s.parse(bytes, s.name);
      ++accepted;
    } catch (const icd::InputError& e) {
      if (std::string(e.what()).rfind(s.name + ": ", 0) != 0) {
        std::fprintf(stderr, "BUG: iteration %ld: message does not start with the source: %s\n", it,
                     e.what());
        return 1;
      }
      ++rejected;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "BUG: iteration %ld (%s): unexpected exception: %s\n", it,
                   s.name.c_str(), e.what());
      return 1;
    }
  }
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "%ld mutants of %zu seeds: %ld parsed, %ld rejected with InputError, 0 bugs (%.1f s)\n",
      iterations, seeds.size(), accepted, rejected, sec);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("fuzz_mesh_readers", run, argc, argv);
}
