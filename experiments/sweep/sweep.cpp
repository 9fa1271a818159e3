#include "experiments/sweep/sweep.hpp"

#include <fnmatch.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include <icd/config.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>
#include <icd/mesh/io/atomic_write.hpp>

#include "experiments/runner/child_process.hpp"

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

namespace icd::sweep {
namespace {

std::atomic<bool> g_stop{false};

std::string read_text(const fs::path& p, std::size_t max_bytes = std::size_t{1} << 30) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError(p.string() + ": cannot open");
  std::string s;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    s.append(buf, static_cast<std::size_t>(in.gcount()));
    if (s.size() > max_bytes) throw InputError(p.string() + ": larger than the limit");
  }
  return s;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

struct Expander {
  std::string source_dir, sweep_dir, bin_dir, data_dir;
  bool identity = false;  ///< leaves the placeholders (the templates hashed into case ids)
  std::string operator()(std::string s) const {
    if (identity) return s;
    s = replace_all(std::move(s), "{source_dir}", source_dir);
    s = replace_all(std::move(s), "{sweep_dir}", sweep_dir);
    s = replace_all(std::move(s), "{bin_dir}", bin_dir);
    return replace_all(std::move(s), "{data_dir}", data_dir);
  }
};

/// A JSON scalar as the text passed to the program.
std::string scalar_text(const ojson& v, const std::string& where) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) {
    std::ostringstream s;
    s.precision(17);
    s << v.get<double>();
    // the shortest text that reads back to the same double
    for (int p = 1; p <= 17; ++p) {
      std::ostringstream t;
      t.precision(p);
      t << v.get<double>();
      if (std::stod(t.str()) == v.get<double>()) return t.str();
    }
    return s.str();
  }
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  throw InputError(where + ": expected a string, number or boolean, got " + v.dump());
}

/// Sorted regular files matching `pattern` (fnmatch on the file name; the
/// folder part is taken literally).
std::vector<std::string> glob_files(const std::string& pattern_template, const Expander& expand,
                                    const std::string& where) {
  const fs::path pattern = expand(pattern_template);
  const fs::path dir = pattern.parent_path();
  const std::string name = pattern.filename().string();
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && fnmatch(name.c_str(), e.path().filename().c_str(), 0) == 0)
      names.push_back(e.path().filename().string());
  if (ec) throw InputError(where + ": cannot list " + dir.string() + ": " + ec.message());
  if (names.empty()) throw InputError(where + ": no file matches " + pattern.string());
  std::sort(names.begin(), names.end());
  const std::string prefix = fs::path(pattern_template).parent_path().string();
  for (std::string& n : names) n = prefix + "/" + n;  // keeps the placeholders: stable across checkouts
  return names;
}

/// Values of one parameter (array of scalars, or {"glob": pattern}).
std::vector<std::pair<std::string, bool>> param_values(const ojson& v, const Expander& expand,
                                                       const std::string& where) {
  std::vector<std::pair<std::string, bool>> out;  // text, is_bool_true/false marker in .second
  auto one = [&](const ojson& x, const std::string& w) {
    if (x.is_boolean()) out.emplace_back(x.get<bool>() ? "true" : "false", true);
    else out.emplace_back(scalar_text(x, w), false);
  };
  if (v.is_array()) {
    if (v.empty()) throw InputError(where + ": empty list of values");
    for (std::size_t i = 0; i < v.size(); ++i) one(v[i], where + "[" + std::to_string(i) + "]");
  } else if (v.is_object() && v.size() == 1 && v.contains("glob") && v["glob"].is_string()) {
    for (const std::string& f : glob_files(v["glob"].get<std::string>(), expand, where + ".glob"))
      out.emplace_back(f, false);
  } else {
    throw InputError(where + ": expected a list of values or {\"glob\": \"pattern\"}");
  }
  return out;
}

struct ParamValue {
  std::string name, text;
  bool is_bool = false;
};

void append_param_args(const ParamValue& p, const Expander& expand, std::vector<std::string>& args) {
  if (p.name.front() == '_') return;  // a label: in the CSV only
  if (p.name.front() == '@') {        // a positional argument (e.g. icd-run's scene)
    args.push_back(expand(p.text));
    return;
  }
  if (p.name.front() == '-') {
    if (p.is_bool) {
      if (p.text == "true") args.push_back(p.name);
      return;
    }
    args.push_back(p.name);
    args.push_back(expand(p.text));
    return;
  }
  args.push_back("--set");  // a scene field
  args.push_back(p.name + "=" + expand(p.text));
}

const std::set<std::string> kTopKeys = {"name",   "title",  "program", "args",
                                        "grid",   "cases",  "inputs",  "collect",
                                        "limits", "accept_exit", "keep_outputs", "comment", "setup",
                                        "measured"};

std::string last_line(const fs::path& p) {
  std::string s;
  try {
    s = read_text(p, std::size_t{64} << 20);
  } catch (const std::exception&) {
    return "";
  }
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  // progress bars rewrite the line with \r: keep the last piece
  const std::size_t nl = s.find_last_of("\n\r");
  std::string line = nl == std::string::npos ? s : s.substr(nl + 1);
  if (line.size() > 300) line = line.substr(0, 300) + "...";
  return escape_bytes(line, 300);
}

// ---- child processes --------------------------------------------------------

/// Runs one case or setup command with the application layer's one spawner
/// (experiments/runner/child_process): its own process group (a timeout or an
/// interrupt kills its children too), `dir` as working directory, stdin from
/// /dev/null, stdout and stderr into files, the sweep's limits (0 = none).
runner::ChildResult spawn_and_wait(const std::vector<std::string>& argv, const fs::path& dir,
                                   const fs::path& out_file, const fs::path& err_file,
                                   const Limits& limits) {
  runner::ChildLimits l;
  l.wall_seconds = limits.wall_seconds;
  l.cpu_seconds = limits.cpu_seconds;
  l.memory_bytes = limits.memory_bytes;
  runner::ChildOptions o;
  o.cwd = dir;
  o.stdout_file = out_file;
  o.stderr_file = err_file;
  o.stdin_null = true;
  o.own_process_group = true;
  o.stop = &g_stop;
  return runner::run_child(argv, l, o);
}

// ---- CSV --------------------------------------------------------------------

std::vector<std::vector<std::string>> parse_csv(const std::string& text, const std::string& what) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row;
  std::string field;
  bool quoted = false, any = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          quoted = false;
        }
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
      any = true;
    } else if (c == ',') {
      row.push_back(std::move(field));
      field.clear();
      any = true;
    } else if (c == '\n' || c == '\r') {
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      if (any || !field.empty()) {
        row.push_back(std::move(field));
        rows.push_back(std::move(row));
      }
      row.clear();
      field.clear();
      any = false;
    } else {
      field += c;
      any = true;
    }
  }
  if (quoted) throw InputError(what + ": unterminated quoted field");
  if (any || !field.empty()) {
    row.push_back(std::move(field));
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos && (s.empty() || (s.front() != ' ' && s.back() != ' ')))
    return s;
  return '"' + replace_all(s, "\"", "\"\"") + '"';
}

std::string md_cell(std::string s) {
  s = replace_all(std::move(s), "|", "\\|");
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

/// Collects the outputs of a successful case into `r` (throws on a problem).
void collect(const Plan& plan, const fs::path& dir, CaseResult& r) {
  const Collect& c = plan.collect;
  if (c.kind.empty()) return;
  if (c.kind == "csv") {
    const fs::path f = dir / "out" / c.file;
    const auto table = parse_csv(read_text(f), f.string());
    if (table.empty()) throw InputError(c.file + ": empty (no header)");
    const auto& header = table.front();
    std::vector<std::size_t> pick;
    if (c.columns.empty()) {
      for (std::size_t i = 0; i < header.size(); ++i) pick.push_back(i);
    } else {
      for (const std::string& col : c.columns) {
        const auto it = std::find(header.begin(), header.end(), col);
        if (it == header.end()) throw InputError(c.file + ": no column \"" + col + "\"");
        pick.push_back(static_cast<std::size_t>(it - header.begin()));
      }
    }
    for (std::size_t i : pick) r.columns.push_back(header[i]);
    std::size_t first = 1;
    if (c.rows == "last" && table.size() > 1) first = table.size() - 1;
    for (std::size_t k = first; k < table.size(); ++k) {
      std::vector<std::string> row;
      for (std::size_t i : pick) row.push_back(i < table[k].size() ? table[k][i] : "");
      r.rows.push_back(std::move(row));
    }
  } else if (c.kind == "json") {
    const fs::path f = dir / "out" / c.file;
    const ojson j = ojson::parse(read_text(f), nullptr, false);
    if (j.is_discarded()) throw InputError(c.file + ": not valid JSON");
    std::vector<std::string> row;
    for (const std::string& ptr : c.columns) {
      const ojson::json_pointer p(ptr);
      if (!j.contains(p)) throw InputError(c.file + ": no field " + ptr);
      const ojson& v = j.at(p);
      r.columns.push_back(ptr.substr(1));
      row.push_back(v.is_string() ? v.get<std::string>() : v.dump());
    }
    r.rows.push_back(std::move(row));
  } else if (c.kind == "log") {
    const std::string log = read_text(dir / "stdout.txt") + "\n" + read_text(dir / "stderr.txt");
    std::vector<std::string> row;
    for (const auto& [col, pattern] : c.patterns) {
      r.columns.push_back(col);
      std::smatch m;
      const std::regex re(pattern, std::regex::ECMAScript | std::regex::multiline);
      row.push_back(std::regex_search(log, m, re) ? (m.size() > 1 ? m[1].str() : m[0].str()) : "");
    }
    r.rows.push_back(std::move(row));
  }
}

}  // namespace

void request_stop() { g_stop = true; }
bool stop_requested() { return g_stop.load(); }

std::string hash_hex(std::string_view bytes) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string shell_quote(const std::string& s) { return "'" + replace_all(s, "'", "'\\''") + "'"; }

Plan load_plan(const fs::path& sweep_file, const fs::path& bin_dir) {
  const std::string where0 = sweep_file.string();
  ojson j;
  try {
    j = ojson::parse(read_text(sweep_file, std::size_t{16} << 20));
  } catch (const ojson::exception& e) {
    throw InputError(where0 + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw InputError(where0 + ": expected a JSON object");
  for (const auto& [k, v] : j.items())
    if (!kTopKeys.count(k)) throw InputError(where0 + ": unknown field \"" + k + "\"");
  auto field = [&](const std::string& k) { return where0 + ": \"" + k + "\""; };
  Plan plan;
  plan.sweep_file = fs::absolute(sweep_file);
  Expander expand{ICD_SOURCE_DIR, plan.sweep_file.parent_path().string(),
                  fs::absolute(bin_dir).string(), ICD_DATA_DIR};
  if (!j.contains("name") || !j["name"].is_string()) throw InputError(field("name") + ": required string");
  plan.name = j["name"].get<std::string>();
  if (plan.name.empty() || plan.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.") != std::string::npos || plan.name[0] == '.')
    throw InputError(field("name") + ": only letters, digits, '_', '-', '.' (it names the output folder)");
  plan.title = j.value("title", plan.name);
  if (!j.contains("program") || !j["program"].is_string()) throw InputError(field("program") + ": required string");
  const std::string program = j["program"].get<std::string>();
  if (program.empty() || program.find('/') != std::string::npos || program[0] == '.')
    throw InputError(field("program") + ": a program name in the build's bin/ folder (no path), got \"" +
                     escape_bytes(program) + "\"");
  plan.program = fs::absolute(bin_dir) / program;
  if (access(plan.program.c_str(), X_OK) != 0)
    throw InputError(field("program") + ": " + plan.program.string() + " is not an executable (not built?)");

  std::vector<std::string> base;  // templates
  if (j.contains("args")) {
    if (!j["args"].is_array()) throw InputError(field("args") + ": expected a list of strings");
    for (std::size_t i = 0; i < j["args"].size(); ++i)
      base.push_back(scalar_text(j["args"][i], field("args") + "[" + std::to_string(i) + "]"));
  }
  if (std::none_of(base.begin(), base.end(), [](const std::string& a) { return a.find("{out}") != std::string::npos; }) &&
      j.contains("collect") &&
      (j["collect"].contains("csv") || j["collect"].contains("json")))
    throw InputError(field("args") + ": collecting a file needs \"{out}\" among the arguments");

  // limits
  if (j.contains("limits")) {
    const ojson& l = j["limits"];
    if (!l.is_object()) throw InputError(field("limits") + ": expected an object");
    for (const auto& [k, v] : l.items()) {
      if (!v.is_number() || v.get<double>() < 0)
        throw InputError(field("limits") + "." + k + ": expected a number >= 0");
      if (k == "wall_seconds") plan.limits.wall_seconds = v.get<double>();
      else if (k == "cpu_seconds") plan.limits.cpu_seconds = v.get<double>();
      else if (k == "memory_mb") plan.limits.memory_bytes = static_cast<std::uint64_t>(v.get<double>() * 1048576.0);
      else throw InputError(field("limits") + ": unknown field \"" + k + "\" (wall_seconds, cpu_seconds, memory_mb)");
    }
  }
  plan.accept_exit = {0};
  if (j.contains("accept_exit")) {
    plan.accept_exit.clear();
    if (!j["accept_exit"].is_array()) throw InputError(field("accept_exit") + ": expected a list of exit statuses");
    for (const auto& v : j["accept_exit"]) {
      if (!v.is_number_integer()) throw InputError(field("accept_exit") + ": expected integers");
      plan.accept_exit.push_back(v.get<int>());
    }
  }
  if (j.contains("keep_outputs")) {
    if (!j["keep_outputs"].is_boolean()) throw InputError(field("keep_outputs") + ": expected true or false");
    plan.keep_outputs = j["keep_outputs"].get<bool>();
  }
  if (j.contains("setup")) {
    const ojson& su = j["setup"];
    if (!su.is_array()) throw InputError(field("setup") + ": expected a list of commands [program, args...]");
    for (std::size_t i = 0; i < su.size(); ++i) {
      const std::string w = field("setup") + "[" + std::to_string(i) + "]";
      if (!su[i].is_array() || su[i].empty()) throw InputError(w + ": expected [program, args...]");
      std::vector<std::string> cmd;
      for (std::size_t k = 0; k < su[i].size(); ++k) cmd.push_back(expand(scalar_text(su[i][k], w)));
      if (cmd[0].empty() || cmd[0].find('/') != std::string::npos || cmd[0][0] == '.')
        throw InputError(w + ": a program name in the build's bin/ folder (no path), got \"" + escape_bytes(cmd[0]) + "\"");
      cmd[0] = (fs::absolute(bin_dir) / cmd[0]).string();
      if (access(cmd[0].c_str(), X_OK) != 0) throw InputError(w + ": " + cmd[0] + " is not an executable (not built?)");
      plan.setup.push_back(std::move(cmd));
    }
  }
  // measured: what the result comparison (compare_results.py) must not
  // compare; icd-sweep itself only checks its form
  if (j.contains("measured")) {
    const ojson& m = j["measured"];
    const std::string w = field("measured");
    auto strings = [&](const ojson& v, const std::string& k) {
      if (!v.is_array() || !std::all_of(v.begin(), v.end(), [](const ojson& x) { return x.is_string(); }))
        throw InputError(w + "." + k + ": expected a list of column names");
    };
    if (!m.is_object()) throw InputError(w + ": expected {\"columns\": [...], \"rows\": {...}, \"stable\": [...]}");
    for (const auto& [k, v] : m.items()) {
      if (k == "columns" || k == "stable") {
        strings(v, k);
      } else if (k == "rows") {
        if (!v.is_object() || !std::all_of(v.begin(), v.end(), [](const ojson& x) { return x.is_string(); }))
          throw InputError(w + ".rows: expected {\"column\": \"value\"}");
      } else {
        throw InputError(w + ": unknown field \"" + k + "\" (columns, rows, stable)");
      }
    }
  }
  // collect
  if (j.contains("collect")) {
    const ojson& c = j["collect"];
    if (!c.is_object()) throw InputError(field("collect") + ": expected an object");
    for (const auto& [k, v] : c.items()) {
      if (k == "csv" || k == "json") {
        if (!plan.collect.kind.empty()) throw InputError(field("collect") + ": one of csv, json, log");
        if (!v.is_string() || v.get<std::string>().empty() || fs::path(v.get<std::string>()).is_absolute() ||
            v.get<std::string>().find("..") != std::string::npos)
          throw InputError(field("collect") + "." + k + ": a file name inside the case's output folder");
        plan.collect.kind = k;
        plan.collect.file = v.get<std::string>();
      } else if (k == "log") {
        if (!plan.collect.kind.empty()) throw InputError(field("collect") + ": one of csv, json, log");
        if (!v.is_object() || v.empty()) throw InputError(field("collect") + ".log: expected {\"column\": \"regex\", ...}");
        plan.collect.kind = "log";
        for (const auto& [col, re] : v.items()) {
          if (!re.is_string()) throw InputError(field("collect") + ".log." + col + ": expected a regex string");
          try {
            (void)std::regex(re.get<std::string>(), std::regex::ECMAScript | std::regex::multiline);
          } catch (const std::regex_error& e) {
            throw InputError(field("collect") + ".log." + col + ": bad regex: " + e.what());
          }
          plan.collect.patterns.emplace_back(col, re.get<std::string>());
        }
      } else if (k == "columns" || k == "fields") {
        if (!v.is_array()) throw InputError(field("collect") + "." + k + ": expected a list of names");
        for (const auto& x : v) {
          if (!x.is_string()) throw InputError(field("collect") + "." + k + ": expected strings");
          plan.collect.columns.push_back(x.get<std::string>());
        }
      } else if (k == "rows") {
        if (!v.is_string() || (v != "all" && v != "last")) throw InputError(field("collect") + ".rows: \"all\" or \"last\"");
        plan.collect.rows = v.get<std::string>();
      } else {
        throw InputError(field("collect") + ": unknown field \"" + k + "\" (csv, json, log, columns, fields, rows)");
      }
    }
    if (plan.collect.kind == "json") {
      if (plan.collect.columns.empty()) throw InputError(field("collect") + ".fields: JSON pointers required for json");
      for (const std::string& p : plan.collect.columns) {
        if (p.empty() || p[0] != '/') throw InputError(field("collect") + ".fields: a JSON pointer (\"/a/b\"), got \"" + p + "\"");
        try {
          (void)ojson::json_pointer(p);
        } catch (const ojson::exception& e) {
          throw InputError(field("collect") + ".fields: \"" + p + "\" is not a JSON pointer: " + e.what());
        }
      }
    }
  }
  // explicit cases x grid points
  std::vector<std::vector<ParamValue>> explicit_cases;
  if (j.contains("cases")) {
    if (!j["cases"].is_array() || j["cases"].empty()) throw InputError(field("cases") + ": expected a non-empty list of objects");
    for (std::size_t i = 0; i < j["cases"].size(); ++i) {
      const ojson& c = j["cases"][i];
      const std::string w = field("cases") + "[" + std::to_string(i) + "]";
      if (!c.is_object()) throw InputError(w + ": expected an object");
      std::vector<ParamValue> ps;
      for (const auto& [k, v] : c.items()) {
        if (k.empty()) throw InputError(w + ": empty parameter name");
        ps.push_back({k, v.is_boolean() ? (v.get<bool>() ? "true" : "false") : scalar_text(v, w + "." + k), v.is_boolean()});
      }
      explicit_cases.push_back(std::move(ps));
    }
  } else {
    explicit_cases.emplace_back();
  }
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, bool>>>> grid;
  if (j.contains("grid")) {
    if (!j["grid"].is_object()) throw InputError(field("grid") + ": expected an object {parameter: [values]}");
    for (const auto& [k, v] : j["grid"].items()) {
      if (k.empty()) throw InputError(field("grid") + ": empty parameter name");
      grid.emplace_back(k, param_values(v, expand, field("grid") + "." + k));
    }
  }
  // input checksums, cached per file
  std::map<std::string, std::string> file_hash;
  auto checksum = [&](const std::string& path) -> std::string {
    auto it = file_hash.find(path);
    if (it != file_hash.end()) return it->second;
    std::error_code ec;
    std::string h;
    if (fs::is_regular_file(path, ec)) h = hash_hex(read_text(path));
    return file_hash[path] = h;
  };
  std::vector<std::string> extra_inputs;
  if (j.contains("inputs")) {
    if (!j["inputs"].is_array()) throw InputError(field("inputs") + ": expected a list of files");
    for (const auto& v : j["inputs"]) {
      if (!v.is_string()) throw InputError(field("inputs") + ": expected strings");
      const std::string p = expand(v.get<std::string>());
      if (checksum(p).empty()) throw InputError(field("inputs") + ": " + p + " is not a readable file");
      extra_inputs.push_back(v.get<std::string>());
    }
  }
  std::size_t points = 1;
  for (const auto& g : grid) points *= g.second.size();
  std::set<std::string> ids;
  std::vector<std::string> names;
  for (const auto& ec : explicit_cases) {
    for (std::size_t p = 0; p < points; ++p) {
      std::vector<ParamValue> ps = ec;
      std::size_t rest = p;
      for (std::size_t gi = grid.size(); gi-- > 0;) {  // the last grid parameter varies fastest
        const auto& vals = grid[gi].second;
        const auto& v = vals[rest % vals.size()];
        rest /= vals.size();
        ps.insert(ps.begin() + static_cast<long>(ec.size()), ParamValue{grid[gi].first, v.first, v.second});
      }
      Case c;
      c.index = plan.cases.size();
      ojson key;
      key["program"] = program;
      key["args"] = base;
      std::vector<std::string> templ = base;
      for (const ParamValue& pv : ps) {
        if (std::find(names.begin(), names.end(), pv.name) == names.end()) names.push_back(pv.name);
        c.params.emplace_back(pv.name, pv.text);
        key["params"].push_back({pv.name, pv.text});
        std::vector<std::string> a;
        append_param_args(pv, Expander{{}, {}, {}, {}, true}, a);  // templates: checksummed below
        templ.insert(templ.end(), a.begin(), a.end());
        append_param_args(pv, expand, c.args);
      }
      std::vector<std::string> args = base;
      for (std::string& a : args) a = expand(a);  // ({out} stays: it is per run)
      args.insert(args.end(), c.args.begin(), c.args.end());
      c.args = std::move(args);
      key["inputs"] = ojson::array();
      for (const std::string& t : extra_inputs) key["inputs"].push_back({t, checksum(expand(t))});
      for (std::size_t i = 0; i < templ.size(); ++i) {
        std::string t = templ[i];
        const std::size_t eq = t.find('=');
        if (i > 0 && templ[i - 1] == "--set" && eq != std::string::npos) t = t.substr(eq + 1);
        if (t.find("{out}") != std::string::npos || t.empty()) continue;
        const std::string h = checksum(expand(t));
        if (!h.empty()) key["inputs"].push_back({t, h});
      }
      c.id = hash_hex(key.dump());
      // The marker's key also holds what is collected and what counts as a
      // result: a changed "collect" or "accept_exit" runs the case again
      // (same id, same folder) instead of keeping rows of the old collection.
      key["collect"] = j.contains("collect") ? j["collect"] : ojson();
      key["accept_exit"] = plan.accept_exit;
      key["keep_outputs"] = plan.keep_outputs;
      c.key = key.dump();
      if (!ids.insert(c.id).second)
        throw InputError(where0 + ": two cases have the same parameters (case " + std::to_string(c.index) + ")");
      plan.cases.push_back(std::move(c));
    }
  }
  plan.param_names = names;
  return plan;
}

std::string CaseResult::to_json() const {
  ojson j;
  j["id"] = id;
  j["status"] = status;
  j["exit_status"] = exit_status;
  j["signal"] = signal;
  j["message"] = message;
  j["wall_seconds"] = wall_seconds;
  j["columns"] = columns;
  j["rows"] = rows;
  j["key"] = key;
  return j.dump(1) + "\n";
}

CaseResult CaseResult::from_json(const std::string& text) {
  const ojson j = ojson::parse(text);
  CaseResult r;
  r.id = j.at("id").get<std::string>();
  r.status = j.at("status").get<std::string>();
  r.exit_status = j.at("exit_status").get<int>();
  r.signal = j.at("signal").get<int>();
  r.message = j.at("message").get<std::string>();
  r.wall_seconds = j.at("wall_seconds").get<double>();
  r.columns = j.at("columns").get<std::vector<std::string>>();
  r.rows = j.at("rows").get<std::vector<std::vector<std::string>>>();
  r.key = j.at("key").get<std::string>();
  return r;
}

fs::path case_dir(const fs::path& out, const Case& c) { return out / "cases" / c.id; }

namespace {
bool read_marker(const fs::path& out, const Case& c, CaseResult& r) {
  const fs::path m = case_dir(out, c) / "result.json";
  std::error_code ec;
  if (!fs::is_regular_file(m, ec)) return false;
  try {
    r = CaseResult::from_json(read_text(m));
  } catch (const std::exception&) {
    return false;  // unreadable marker: run again
  }
  return r.key == c.key && r.id == c.id;
}
}  // namespace

bool finished(const fs::path& out, const Case& c, CaseResult* result) {
  CaseResult r;
  if (!read_marker(out, c, r) || r.status != "ok") return false;
  if (result) *result = std::move(r);
  return true;
}

CaseResult run_case(const Plan& plan, const Case& c, const fs::path& out) {
  const fs::path final_dir = case_dir(out, c);
  const fs::path tmp = final_dir.string() + ".tmp";
  CaseResult r;
  r.id = c.id;
  r.key = c.key;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    fs::remove_all(tmp);
    fs::create_directories(tmp / "out");
    std::vector<std::string> argv{plan.program.string()};
    for (const std::string& a : c.args) argv.push_back(replace_all(a, "{out}", (tmp / "out").string()));
    ojson info;
    info["id"] = c.id;
    info["index"] = c.index;
    info["params"] = c.params;
    info["argv"] = argv;
    write_file_atomically(tmp / "case.json", info.dump(1) + "\n");
    const runner::ChildResult s = spawn_and_wait(argv, tmp, tmp / "stdout.txt", tmp / "stderr.txt", plan.limits);
    r.exit_status = s.exit_status;
    r.signal = s.signal;
    const bool accepted = s.exit_status >= 0 && std::find(plan.accept_exit.begin(), plan.accept_exit.end(),
                                                          s.exit_status) != plan.accept_exit.end();
    if (s.timed_out) {
      r.status = "timeout";
      char buf[128];
      std::snprintf(buf, sizeof buf, "killed after its wall-clock limit of %g s", plan.limits.wall_seconds);
      r.message = buf;
    } else if (s.stopped) {
      r.status = "killed";
      r.message = "stopped (icd-sweep was interrupted)";
    } else if (s.signal != 0) {
      r.status = "killed";
      r.message = "killed by signal " + std::to_string(s.signal) + " (" + strsignal(s.signal) + ")";
      if (s.signal == SIGXCPU) r.message += ": CPU-time limit";
      const std::string l = last_line(tmp / "stderr.txt");
      if (!l.empty()) r.message += ": " + l;
    } else if (!accepted) {
      r.status = "failed";
      r.message = "exited with status " + std::to_string(s.exit_status);
      std::string l = last_line(tmp / "stderr.txt");
      if (l.empty()) l = last_line(tmp / "stdout.txt");
      if (!l.empty()) r.message += ": " + l;
    } else {
      r.status = "ok";
      try {
        collect(plan, tmp, r);
      } catch (const std::exception& e) {
        r.status = "failed";
        r.message = std::string("collecting outputs: ") + e.what();
        r.columns.clear();
        r.rows.clear();
      }
    }
    if (!plan.keep_outputs) fs::remove_all(tmp / "out");
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    write_file_atomically(tmp / "result.json", r.to_json());
    fs::remove_all(final_dir);
    fs::rename(tmp, final_dir);  // the case appears complete, or not at all
  } catch (const std::exception& e) {
    r.status = "failed";
    r.message = e.what();
    r.columns.clear();
    r.rows.clear();
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    try {  // recorded like any other failure (best effort: the folder may be what failed)
      fs::create_directories(tmp);
      write_file_atomically(tmp / "result.json", r.to_json());
      fs::remove_all(final_dir);
      fs::rename(tmp, final_dir);
    } catch (const std::exception&) {
    }
  }
  return r;
}

void run_setup(const Plan& plan, const fs::path& out) {
  for (std::size_t k = 0; k < plan.setup.size(); ++k) {
    const fs::path dir = out / "setup" / std::to_string(k);
    std::vector<std::string> argv = plan.setup[k];
    for (std::string& a : argv) a = replace_all(a, "{out}", (dir / "out").string());
    ojson key = argv;
    const std::string marker = hash_hex(key.dump());
    std::error_code ec;
    if (fs::is_regular_file(dir / ("done-" + marker), ec)) continue;
    fs::remove_all(dir);
    fs::create_directories(dir / "out");
    const runner::ChildResult s = spawn_and_wait(argv, dir, dir / "stdout.txt", dir / "stderr.txt", plan.limits);
    if (s.exit_status != 0) {
      std::string l = last_line(dir / "stderr.txt");
      if (l.empty()) l = last_line(dir / "stdout.txt");
      throw InputError("setup command " + std::to_string(k) + " (" + fs::path(argv[0]).filename().string() +
                       ") " + (s.timed_out ? "ran over its time limit" : s.signal ? "was killed by signal " + std::to_string(s.signal) : "exited with status " + std::to_string(s.exit_status)) +
                       (l.empty() ? "" : ": " + l) + " (log: " + dir.string() + ")");
    }
    write_file_atomically(dir / ("done-" + marker), key.dump() + "\n");
  }
}

std::vector<CaseResult> read_results(const Plan& plan, const fs::path& out) {
  std::vector<CaseResult> rs;
  for (const Case& c : plan.cases) {
    CaseResult r;
    if (read_marker(out, c, r)) rs.push_back(std::move(r));
  }
  return rs;
}

int gather(const Plan& plan, std::vector<CaseResult> results, const fs::path& out) {
  std::map<std::string, CaseResult> by_id;
  for (CaseResult& r : results) by_id[r.id] = std::move(r);
  std::vector<const Case*> order;
  for (const Case& c : plan.cases) order.push_back(&c);
  std::sort(order.begin(), order.end(), [](const Case* a, const Case* b) { return a->id < b->id; });
  std::vector<std::string> columns;
  for (const auto& [id, r] : by_id)
    for (const std::string& col : r.columns)
      if (std::find(columns.begin(), columns.end(), col) == columns.end()) columns.push_back(col);
  std::ostringstream csv;
  csv << "case_id";
  for (const std::string& n : plan.param_names) csv << ',' << csv_field(n);
  csv << ",status,exit_status,message";
  for (const std::string& col : columns) csv << ',' << csv_field(col);
  csv << '\n';
  int not_ok = 0;
  std::vector<std::string> failures;
  double total_wall = 0;
  std::vector<double> walls;
  for (const Case* c : order) {
    auto it = by_id.find(c->id);
    CaseResult missing;
    if (it == by_id.end()) {
      missing.id = c->id;
      missing.status = "missing";
      missing.message = "no result (case not run, or its run did not finish)";
    }
    const CaseResult& r = it == by_id.end() ? missing : it->second;
    if (r.status != "ok") {
      ++not_ok;
      failures.push_back("- `" + c->id + "` (case " + std::to_string(c->index) + "): " + r.status + ": " + md_cell(r.message));
    } else {
      total_wall += r.wall_seconds;
      walls.push_back(r.wall_seconds);
    }
    std::ostringstream prefix;
    prefix << c->id;
    for (const std::string& n : plan.param_names) {
      std::string v;
      for (const auto& [k, val] : c->params)
        if (k == n) v = val;
      prefix << ',' << csv_field(v);
    }
    prefix << ',' << r.status << ',' << r.exit_status << ',' << csv_field(r.message);
    const std::size_t nrows = std::max<std::size_t>(1, r.rows.size());
    for (std::size_t k = 0; k < nrows; ++k) {
      csv << prefix.str();
      for (const std::string& col : columns) {
        std::string v;
        if (k < r.rows.size()) {
          const auto ci = std::find(r.columns.begin(), r.columns.end(), col);
          if (ci != r.columns.end() && static_cast<std::size_t>(ci - r.columns.begin()) < r.rows[k].size())
            v = r.rows[k][static_cast<std::size_t>(ci - r.columns.begin())];
        }
        csv << ',' << csv_field(v);
      }
      csv << '\n';
    }
  }
  fs::create_directories(out);
  write_file_atomically(out / "results.csv", csv.str());
  // the markdown section for the results index
  std::sort(walls.begin(), walls.end());
  std::ostringstream md;
  md << "## " << md_cell(plan.title) << "\n\n";
  md << "Sweep `" << plan.sweep_file.filename().string() << "`: program `" << plan.program.filename().string()
     << "`, " << plan.cases.size() << " cases, " << plan.cases.size() - static_cast<std::size_t>(not_ok)
     << " ok, " << not_ok << " not ok. ";
  if (!walls.empty()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "Case wall time: median %.3g s, total %.3g s (ok cases). ",
                  walls[walls.size() / 2], total_wall);
    md << buf;
  }
  md << "Table: [results.csv](results.csv) (one row per collected row, sorted by case id).\n\n";
  const auto table = parse_csv(csv.str(), "results.csv");
  const std::size_t max_rows = 40;
  for (std::size_t k = 0; k < table.size() && k <= max_rows; ++k) {
    md << '|';
    for (const std::string& f : table[k]) md << ' ' << md_cell(f) << " |";
    md << '\n';
    if (k == 0) {
      md << '|';
      for (std::size_t i = 0; i < table[k].size(); ++i) md << "---|";
      md << '\n';
    }
  }
  if (table.size() > max_rows + 1) md << "\n(" << table.size() - 1 - max_rows << " more rows in results.csv)\n";
  if (!failures.empty()) {
    md << "\nNot ok:\n\n";
    for (const std::string& f : failures) md << f << '\n';
  }
  write_file_atomically(out / "results.md", md.str());
  return not_ok;
}

}  // namespace icd::sweep
