// The scene document layer: nlohmann-json with comments, duplicate keys
// refused, limits, includes and --set overrides.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "experiments/runner/scene.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::runner {
namespace {

namespace fs = std::filesystem;

template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("icd_scene_json_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

const char* kSphere = R"({"name": "a", "primitive": {"type": "sphere", "radius": 0.1}})";

TEST(SceneJson, ParsesNestedDocumentWithComments) {
  const Json j = parse_json(
      "// a scene\n{\"a\": [1, -2.5e3, true, null], /* inline */ \"b\": {\"c\": \"x\\\"y\\u00e9\"}}",
      "t");
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j.at("a").size(), 4u);
  EXPECT_EQ(j.at("a")[0].get<double>(), 1.0);
  EXPECT_EQ(j.at("a")[1].get<double>(), -2500.0);
  EXPECT_TRUE(j.at("a")[2].get<bool>());
  EXPECT_TRUE(j.at("a")[3].is_null());
  EXPECT_EQ(j.at("b").at("c").get<std::string>(), "x\"y\xc3\xa9");
}

// Each malformed document raises InputError naming source, line and column.
TEST(SceneJson, MalformedInputsGiveLocatedErrors) {
  const struct {
    const char* text;
    const char* expect;
  } cases[] = {
      {"{\"a\": 1,}", "t:1:9: syntax error"},
      {"{\"a\" 1}", "expected ':'"},
      {"[1, 2", "t:1:6:"},
      {"\"abc", "missing closing quote"},
      {"01", "t:1:2:"},
      {"1.", "invalid number"},
      {"nul", "invalid literal"},
      {"{\"a\": \"\xC3\"}", "ill-formed UTF-8 byte"},
      {"\"\xED\xA0\x80\"", "ill-formed UTF-8 byte"},
      {"\"\xC0\xAF\"", "ill-formed UTF-8 byte"},
      {"", "unexpected end of input"},
      {"\n\n  ]", "t:3:3:"},
      {"{\"a\": 1 /* unterminated", "comment"},
  };
  // nlohmann stops at a NUL byte; the reader refuses it instead of ignoring the rest.
  for (const std::string text : {std::string("{\"a\": 1}\0{\"b\"", 13), std::string("\"a\0b\"", 5)}) {
    const std::string msg = input_error([&] { parse_json(text, "t"); });
    EXPECT_NE(msg.find("unexpected character '\\x00'"), std::string::npos) << msg;
  }
  for (const auto& c : cases) {
    const std::string msg = input_error([&] { parse_json(c.text, "t"); });
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.text << " -> " << msg;
    EXPECT_EQ(msg.rfind("t:", 0), 0u) << msg;
  }
}

TEST(SceneJson, DuplicateKeysAreRefusedWithTheirPath) {
  EXPECT_NE(input_error([] { parse_json(R"({"a": 1, "a": 2})", "t"); })
                .find("t: a: duplicate key \"a\""),
            std::string::npos);
  const std::string msg = input_error(
      [] { parse_json(R"({"objects": [{"n": 1}, {"m": {"x": 1, "y": 2, "x": 3}}]})", "t"); });
  EXPECT_NE(msg.find("t: objects[1].m.x: duplicate key \"x\""), std::string::npos) << msg;
  // The same key in different objects is fine.
  EXPECT_NO_THROW(parse_json(R"({"a": {"k": 1}, "b": {"k": 2}, "k": [{"k": 3}]})", "t"));
}

// Beyond the double range: the field is named (nlohmann refuses overflow
// while parsing); underflow is 0.
TEST(SceneJson, NumbersBeyondTheDoubleRange) {
  const Json j = parse_json("[1e-999, -1e-400, 0.0000e99999]", "t");
  EXPECT_EQ(j[0].get<double>(), 0.0);
  EXPECT_EQ(j[1].get<double>(), 0.0);
  EXPECT_EQ(j[2].get<double>(), 0.0);
  std::string msg = input_error([] { parse_json(R"({"objects": [{"a": 1}, {"young": 1e999}]})", "t"); });
  EXPECT_NE(msg.find("t: objects[1].young: must be a finite number"), std::string::npos) << msg;
  msg = input_error([] { parse_json(R"({"v": [1, 2, -1e400]})", "t"); });
  EXPECT_NE(msg.find("t: v[2]: must be a finite number"), std::string::npos) << msg;
  EXPECT_EQ(parse_json("\"\xC3\xA9\xF0\x9F\x98\x80\"", "t").get<std::string>(),
            "\xC3\xA9\xF0\x9F\x98\x80");
}

TEST(SceneJson, TooManyValuesAreRefused) {
  std::string many = "[0";
  for (int i = 0; i < (1 << 20); ++i) many += ",0";
  many += "]";
  EXPECT_NE(input_error([&] { parse_json(many, "many"); }).find("more than 1048576 values"),
            std::string::npos);
}

TEST(SceneJson, DeepNestingIsRejectedNotOverflowed) {
  const std::string deep(100000, '[');
  EXPECT_NE(input_error([&] { parse_json(deep, "deep"); }).find("nesting deeper than 64"),
            std::string::npos);
  std::string ok;
  for (int i = 0; i < 64; ++i) ok += "[";
  for (int i = 0; i < 64; ++i) ok += "]";
  EXPECT_NO_THROW(parse_json(ok, "ok"));
}

TEST(SceneJson, MissingFileNamesThePath) {
  EXPECT_NE(input_error([] { read_json_file("/nonexistent/scene.json"); })
                .find("/nonexistent/scene.json"),
            std::string::npos);
}

TEST(SceneJson, UnknownFieldSuggestsTheClosestKnownOne) {
  const std::string msg = input_error([] {
    parse_scene(parse_json(std::string("{\"objects\": [") + kSphere + "], \"frmes\": 3}", "s.json"),
                "s.json", ".");
  });
  EXPECT_NE(msg.find("s.json: frmes: unknown field (did you mean \"frames\"?)"), std::string::npos)
      << msg;
  const std::string far = input_error([] {
    parse_scene(parse_json(std::string("{\"objects\": [") + kSphere + "], \"zzzzzz\": 3}", "s.json"),
                "s.json", ".");
  });
  EXPECT_NE(far.find("zzzzzz: unknown field"), std::string::npos);
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
}

TEST(SceneJson, IncludesMergeWithTheIncludingFileWinning) {
  const fs::path d = temp_dir("include");
  write(d / "parts" / "base.json",
        std::string("// shared\n{\"frames\": 5, \"frame_rate\": 30, \"objects\": [") + kSphere +
            "], \"collision\": {\"budget_tests\": 100, \"mode\": \"priority\"}}");
  write(d / "parts" / "mid.json",
        R"({"include": "base.json", "frame_rate": 50, "collision": {"mode": "depth_first"}})");
  write(d / "top.json", R"({"include": ["parts/mid.json"], "frames": 9})");
  const Scene s = load_scene(d / "top.json");
  EXPECT_EQ(s.frames, 9);                       // top wins
  EXPECT_DOUBLE_EQ(s.world.frame_rate, 50);     // mid wins over base
  EXPECT_EQ(s.world.collision.query.budget_tests, 100);  // deep merge keeps base's key
  EXPECT_EQ(s.world.collision.query.mode, collision::TraversalMode::DepthFirst);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_DOUBLE_EQ(s.objects[0].primitive->radius, 0.1);
}

TEST(SceneJson, IncludeCyclesDepthAndBadValuesAreRefused) {
  const fs::path d = temp_dir("cycle");
  write(d / "a.json", R"({"include": "b.json"})");
  write(d / "b.json", R"({"include": "./a.json"})");
  std::string msg = input_error([&] { load_scene(d / "a.json"); });
  EXPECT_NE(msg.find("include: cycle"), std::string::npos) << msg;
  for (int i = 0; i < 12; ++i)
    write(d / ("c" + std::to_string(i) + ".json"),
          "{\"include\": \"c" + std::to_string(i + 1) + ".json\"}");
  write(d / "c12.json", "{}");
  msg = input_error([&] { load_scene(d / "c0.json"); });
  EXPECT_NE(msg.find("nested more than 8 deep"), std::string::npos) << msg;
  write(d / "n.json", R"({"include": 3})");
  msg = input_error([&] { load_scene(d / "n.json"); });
  EXPECT_NE(msg.find("n.json: include: must be a file path"), std::string::npos) << msg;
  write(d / "m.json", R"({"include": "missing.json"})");
  msg = input_error([&] { load_scene(d / "m.json"); });
  EXPECT_NE(msg.find("missing.json"), std::string::npos) << msg;
  // parse_scene alone (no file) refuses an include instead of ignoring it.
  msg = input_error([] {
    parse_scene(parse_json(std::string("{\"include\": \"x.json\", \"objects\": [") + kSphere + "]}", "s"),
                "s", ".");
  });
  EXPECT_NE(msg.find("s: include:"), std::string::npos) << msg;
}

TEST(SceneJson, OverridesSetValuesOfEveryType) {
  const fs::path d = temp_dir("set");
  write(d / "s.json", std::string("{\"frames\": 5, \"objects\": [") + kSphere + ", " +
                          R"({"name": "b", "primitive": {"type": "sphere"}, "position": [1, 0, 0]}]})");
  const Scene s = load_scene(d / "s.json", {"frames=12", "objects.1.material.young=2e5",
                                            "objects.0.position=[0, 0.5, 1]", "name=probe run",
                                            "collision.swept=false", "objects.1.name=\"7\""});
  EXPECT_EQ(s.frames, 12);
  EXPECT_DOUBLE_EQ(s.objects[1].material.young, 2e5);
  EXPECT_EQ(s.objects[0].position, Eigen::Vector3d(0, 0.5, 1));
  EXPECT_EQ(s.name, "probe run");  // not JSON: taken as a string
  EXPECT_FALSE(s.world.collision.swept);
  EXPECT_EQ(s.objects[1].name, "7");  // a JSON string
  EXPECT_EQ(s.objects[0].name, "a");  // untouched
  // Overrides apply after includes.
  write(d / "inc.json", R"({"include": "s.json", "frames": 7})");
  EXPECT_EQ(load_scene(d / "inc.json", {"frames=8"}).frames, 8);
  EXPECT_EQ(load_scene(d / "inc.json").frames, 7);
  // key=null removes the key: the default applies, and a budget in seconds
  // can be swapped for a test budget (both at once are refused).
  write(d / "b.json", std::string("{\"frames\": 5, \"collision\": {\"budget_seconds\": 0.002}, "
                                  "\"objects\": [") + kSphere + "]}");
  EXPECT_EQ(load_scene(d / "b.json", {"frames=null"}).frames, Scene{}.frames);
  EXPECT_NE(input_error([&] { load_scene(d / "b.json", {"collision.budget_tests=400"}); })
                .find("contradict"),
            std::string::npos);
  const Scene t = load_scene(d / "b.json", {"collision.budget_seconds=null", "collision.budget_tests=400"});
  EXPECT_EQ(t.world.collision.query.budget_tests, 400);
  EXPECT_EQ(load_scene(d / "b.json").world.collision.query.budget_seconds, 0.002);
  EXPECT_EQ(load_scene(d / "b.json", {"collision.nothing=null"}).frames, 5);  // absent: nothing to remove
}

TEST(SceneJson, BadOverridesAreRefusedNamingTheKey) {
  const fs::path d = temp_dir("set_bad");
  write(d / "s.json", std::string("{\"objects\": [") + kSphere + "]}");
  const fs::path p = d / "s.json";
  auto msg = [&](const std::string& o) { return input_error([&] { load_scene(p, {o}); }); };
  // Unknown keys: the same check and wording as in a file.
  EXPECT_NE(msg("objects.0.matrial.young=3").find("objects[0].matrial: unknown field (did you mean \"material\"?)"),
            std::string::npos)
      << msg("objects.0.matrial.young=3");
  EXPECT_NE(msg("objects.0.material.yuong=3").find("objects[0].material.yuong: unknown field"),
            std::string::npos);
  // Bad values: the field's own check names it.
  EXPECT_NE(msg("objects.0.material.young=-1").find("objects[0].material.young: must be in (0"),
            std::string::npos);
  EXPECT_NE(msg("frames=lots").find("frames: must be a number, got string"), std::string::npos);
  EXPECT_NE(msg("objects.0.position=[1, 2]").find("objects[0].position: must be an array of 3"),
            std::string::npos);
  // Malformed overrides name the override.
  EXPECT_NE(msg("objects.3.young=1").find("--set objects.3.young=1: objects[3]: index past the end"),
            std::string::npos)
      << msg("objects.3.young=1");
  EXPECT_NE(msg("objects.x=1").find("objects is an array: expected an index"), std::string::npos);
  EXPECT_NE(msg("frames").find("expected key=value"), std::string::npos);
  EXPECT_NE(msg("objects.0.name.x=1").find("objects[0].name is a string"), std::string::npos);
  EXPECT_NE(msg("a..b=1").find("empty part"), std::string::npos);
}

}  // namespace
}  // namespace icd::runner
