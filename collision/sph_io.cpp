#include <icd/collision/sph_io.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

namespace icd::collision {
namespace {

// Number of nodes of a complete `branch`-ary tree with `levels` levels, or -1
// if it exceeds `cap`.
long long complete_count(int levels, int branch, long long cap) {
  long long total = 0, width = 1;
  for (int l = 0; l < levels; ++l) {
    total += width;
    if (total > cap) return -1;
    if (width > cap / branch + 1)
      width = cap + 1;
    else
      width *= branch;
  }
  return total;
}

bool next_content_line(std::istream& in, std::string& line, long long& line_no) {
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.starts_with(kUtf8Bom)) line.erase(0, kUtf8Bom.size());
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '#') continue;
    return true;
  }
  return false;
}

// Parses a whole token as a double. strtod, unlike operator>>, accepts "nan"
// and "inf", so such values reach the finiteness check and are named there.
bool parse_double(const std::string& token, double& value) {
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return !token.empty() && end == token.c_str() + token.size();
}

}  // namespace

SphereTree read_sph(std::istream& in, const std::string& name, const SphReadOptions& options) {
  auto fail = [&](long long line_no, const std::string& what) -> void {
    throw InputError(name + ": line " + std::to_string(line_no) + ": " + what);
  };
  std::string line;
  long long line_no = 0;
  if (!next_content_line(in, line, line_no))
    throw InputError(name + ": empty file, expected header `levels branch`");
  long long levels = 0, branch = 0;
  {
    std::istringstream hs(line);
    if (!(hs >> levels >> branch)) fail(line_no, "header must be `levels branch` (two integers)");
  }
  if (levels < 1 || levels > options.max_levels)
    fail(line_no, "levels = " + std::to_string(levels) + " outside [1, " +
                      std::to_string(options.max_levels) + "]");
  if (branch < 1 || branch > options.max_branch)
    fail(line_no, "branch = " + std::to_string(branch) + " outside [1, " +
                      std::to_string(options.max_branch) + "]");
  const long long expected =
      complete_count(static_cast<int>(levels), static_cast<int>(branch), options.max_lines);
  if (expected < 0)
    fail(line_no, "header declares more than " + std::to_string(options.max_lines) + " node lines");

  // Read node lines; keep only used nodes, remembering their complete index.
  SphereTree tree;
  std::vector<int32_t> parent;
  long long count = 0;
  long long level_begin = 0, level_width = 1;
  int level = 0;
  std::vector<int32_t> compact_prev;  // complete index (within previous level) -> compact id or -1
  std::vector<int32_t> compact_cur;
  while (next_content_line(in, line, line_no)) {
    if (count >= expected) {
      // A text after the complete node list (the toolkit's programs append
      // their options and evaluation, starting "Options :") ends the tree;
      // one more line that starts with a number is an extra node line.
      std::istringstream first(line);
      std::string token;
      double ignored = 0;
      first >> token;
      if (!parse_double(token, ignored)) break;
      fail(line_no,
           "more node lines than the " + std::to_string(expected) + " declared by the header");
    }
    std::istringstream ls(line);
    double x, y, z, r, occ;
    std::string tx, ty, tz, tr;
    if (!(ls >> tx >> ty >> tz >> tr) || !parse_double(tx, x) || !parse_double(ty, y) ||
        !parse_double(tz, z) || !parse_double(tr, r))
      fail(line_no, "expected `x y z r occupancy`");
    if (!(ls >> occ)) occ = 0.0;
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !std::isfinite(r))
      fail(line_no, "node " + std::to_string(count) + " has a non-finite value");
    const long long in_level = count - level_begin;
    int32_t my_compact = -1;
    if (r >= 0.0) {
      int32_t par = -1;
      if (level > 0) {
        const long long p_in_level = in_level / branch;
        par = compact_prev[static_cast<std::size_t>(p_in_level)];
        if (par < 0)
          fail(line_no, "node " + std::to_string(count) + " is used but its parent is unused");
      }
      my_compact = static_cast<int32_t>(tree.spheres.size());
      tree.spheres.push_back({x, y, z, r});
      parent.push_back(par);
    } else if (count == 0) {
      fail(line_no, "the root (node 0) is unused (r < 0)");
    }
    compact_cur.push_back(my_compact);
    ++count;
    if (count - level_begin == level_width) {  // level finished
      compact_prev.swap(compact_cur);
      compact_cur.clear();
      level_begin = count;
      level_width *= branch;
      ++level;
    }
  }
  if (count != expected)
    throw InputError(name + ": " + std::to_string(count) + " node lines, but the header (levels " +
                     std::to_string(levels) + ", branch " + std::to_string(branch) + ") declares " +
                     std::to_string(expected));
  // Trailing levels without any used node simply produce no nodes.
  build_topology(tree, parent);
  tree.rest_spheres = tree.spheres;
  return tree;
}

SphereTree read_sph(const std::string& path, const SphReadOptions& options) {
  check_input_file(path, file_limits::kSph, "sphere tree");
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open file");
  return read_sph(in, path, options);
}

void write_sph(std::ostream& out, const SphereTree& tree, int branch) {
  validate(tree);
  int max_children = 0;
  for (int32_t c : tree.child_count) max_children = std::max(max_children, static_cast<int>(c));
  if (branch == 0) branch = std::max(2, max_children);
  if (branch < max_children)
    throw ParameterError("write_sph: branch " + std::to_string(branch) + " < largest child count " +
                         std::to_string(max_children));
  const int levels = tree.num_levels();
  // Complete index of each compact node, level by level.
  std::vector<long long> complete(tree.spheres.size());
  complete[0] = 0;
  for (int i = 0; i < tree.num_nodes(); ++i)
    for (int c = 0; c < tree.child_count[i]; ++c)
      complete[tree.first_child[i] + c] = complete[i] * branch + 1 + c;
  out << levels << ' ' << branch << '\n';
  out << std::setprecision(17);
  int next = 0;  // next compact node in breadth-first order
  long long total = 0, width = 1;
  for (int l = 0; l < levels; ++l) {
    total += width;
    width *= branch;
  }
  for (long long k = 0; k < total; ++k) {
    if (next < tree.num_nodes() && complete[next] == k) {
      const Sphere& s = tree.spheres[next];
      out << s.x << ' ' << s.y << ' ' << s.z << ' ' << s.r << " 0\n";
      ++next;
    } else {
      out << "0 0 0 -1 0\n";
    }
  }
}

void write_sph(const std::string& path, const SphereTree& tree, int branch) {
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot open file for writing");
  write_sph(out, tree, branch);
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace icd::collision
