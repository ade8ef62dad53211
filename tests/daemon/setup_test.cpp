// tool.list / tool.set and offsets.get / offsets.set against the real daemon.
#include <fstream>
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

TEST_F(MachineTest, ToolListShowsTheTable) {
  const json r = result_of(call("tool.list"));
  EXPECT_EQ(r["units"], "mm");
  ASSERT_EQ(r["tools"].size(), 3u);
  EXPECT_EQ(r["tools"][1]["number"], 2);
  EXPECT_EQ(r["tools"][1]["pocket"], 2);
  EXPECT_EQ(r["tools"][1]["offset"]["z"], 10.0);
  EXPECT_EQ(r["tools"][1]["diameter"], 3.0);
  EXPECT_EQ(r["tools"][1]["comment"], "3 mm drill");
}

TEST_F(MachineTest, ToolSetRewritesTheTableAndTheInterpreterUsesIt) {
  ready_machine();
  const json r = call(
      "tool.set",
      {{"number", 2}, {"offset", {{"z", 12.5}}}, {"diameter", 3.2}, {"comment", "3.2 mm drill"}});
  ASSERT_TRUE(r.contains("result")) << r.dump();
  const auto table = slurp(dir_.path() / "sim_mm.tbl");
  EXPECT_NE(table.find("T2 P2 Z+12.500000 D3.200000 ;3.2 mm drill\n"), std::string::npos) << table;
  EXPECT_NE(table.find("T1 P1 Z+0.000000 D6.000000 ;6 mm end mill\n"), std::string::npos) << table;
  // A new tool gets its number as pocket.
  result_of(call("tool.set", {{"number", 7}, {"offset", {{"z", 1.25}}}}));
  const json tools = result_of(call("tool.list"))["tools"];
  ASSERT_EQ(tools.size(), 4u);
  EXPECT_EQ(tools[3]["number"], 7);
  EXPECT_EQ(tools[3]["pocket"], 7);

  mdi("M61 Q2 G43");  // the tool is in the spindle: no change to wait for
  EXPECT_EQ(status()["tool"]["length_offset"]["z"], 12.5);

  // A restarted daemon reads the new table.
  EXPECT_EQ(daemon_.stop(), 0);
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  ASSERT_EQ(client_.connect(daemon_.socket()), "");
  const json again = result_of(call("tool.list"))["tools"];
  ASSERT_EQ(again.size(), 4u);
  EXPECT_EQ(again[1]["offset"]["z"], 12.5);
  EXPECT_EQ(again[1]["comment"], "3.2 mm drill");
}

TEST_F(MachineTest, ToolDataSetByG10L1IsWrittenToTheTable) {
  ready_machine();
  mdi("G10 L1 P3 Z30 R4");
  const auto table = slurp(dir_.path() / "sim_mm.tbl");
  EXPECT_NE(table.find("T3 P3 Z+30.000000 D8.000000 ;10 mm face mill\n"), std::string::npos)
      << table;
  EXPECT_EQ(result_of(call("tool.list"))["tools"][2]["offset"]["z"], 30.0);
}

TEST_F(MachineTest, ToolSetRejectsBadValuesClearly) {
  const auto before = slurp(dir_.path() / "sim_mm.tbl");
  const std::vector<std::pair<json, std::string>> cases = {
      {json{{"offset", {{"z", 1}}}}, "\"number\" is missing"},
      {json{{"number", 0}}, "\"number\" must be an integer from 1"},
      {json{{"number", 1.5}}, "\"number\" must be an integer"},
      {json{{"number", 1}, {"offset", {{"a", 1}}}}, "axis \"a\", which this machine lacks"},
      {json{{"number", 1}, {"offset", {{"z", "long"}}}}, "\"offset.z\" must be a number"},
      {json{{"number", 1}, {"diameter", -1}}, "\"diameter\" must be a number from 0"},
      {json{{"number", 1}, {"comment", "two\nlines"}}, "\"comment\" must be one line"},
      {json{{"number", 1}, {"length", 3}}, "unknown parameter \"length\""},
  };
  for (const auto& [params, message] : cases) {
    const json r = call("tool.set", params);
    EXPECT_EQ(error_code(r), -32602) << params.dump();
    const std::string text = r["error"].value("message", "");
    EXPECT_NE(text.find(message), std::string::npos) << params.dump() << ": " << text;
  }
  EXPECT_EQ(slurp(dir_.path() / "sim_mm.tbl"), before);
}

TEST_F(MachineTest, SetupIsRefusedWhileAProgramRuns) {
  ready_machine();
  const auto program = dir_.write("long.ngc", "G21 G90 G1 F600 X100\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  EXPECT_EQ(error_code(call("tool.set", {{"number", 1}, {"diameter", 5}})), 1004);
  EXPECT_EQ(error_code(call("offsets.set", {{"system", "G54"}, {"origin", {{"x", 1}}}})), 1004);
  result_of(call("program.abort"));
  EXPECT_EQ(result_of(call("tool.list"))["tools"][0]["diameter"], 6.0);
}

TEST_F(MachineTest, OffsetsGetListsEverySystemAndG92) {
  ready_machine();
  mdi("G0 X3");
  mdi("G92 X1");
  const json r = result_of(call("offsets.get"));
  EXPECT_EQ(r["active"], "G54");
  ASSERT_EQ(r["systems"].size(), 9u);
  EXPECT_EQ(r["systems"][0]["name"], "G54");
  EXPECT_EQ(r["systems"][8]["name"], "G59.3");
  EXPECT_EQ(r["systems"][8]["index"], 9);
  EXPECT_TRUE(r["systems"][3]["origin"].contains("z"));
  EXPECT_EQ(r["g92"]["x"], 2.0);
}

TEST_F(MachineTest, OffsetsSetActsLikeG10L2AndIsSaved) {
  ready_machine();
  mdi("G0 X10 Y10 Z10");
  const json r = call("offsets.set", {{"system", "G55"}, {"origin", {{"x", 5}, {"z", -2.5}}}});
  ASSERT_TRUE(r.contains("result")) << r.dump();
  const json g55 = result_of(call("offsets.get"))["systems"][1];
  EXPECT_EQ(g55["origin"]["x"], 5.0);
  EXPECT_EQ(g55["origin"]["y"], 0.0);
  EXPECT_EQ(g55["origin"]["z"], -2.5);
  const auto vars = slurp(dir_.path() / "sim_mm.var");
  EXPECT_NE(vars.find("5241\t5.000000"), std::string::npos) << vars;
  EXPECT_NE(vars.find("5243\t-2.500000"), std::string::npos) << vars;
  mdi("G55");
  json s = status();
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(s["work_position"]["commanded"]["z"].get<double>(), 12.5, 1e-9);
  // The active system changes at once; the machine does not move.
  result_of(call("offsets.set", {{"system", 2}, {"origin", {{"y", 4}}}}));
  s = status();
  EXPECT_NEAR(s["work_position"]["commanded"]["y"].get<double>(), 6.0, 1e-9);
  EXPECT_EQ(s["position"]["commanded"]["y"], 10.0);
  mdi("G0 Y0");
  EXPECT_NEAR(status()["position"]["commanded"]["y"].get<double>(), 4.0, 1e-9);
}

TEST_F(MachineTest, OffsetsSetRejectsBadValuesClearly) {
  const std::vector<std::pair<json, std::string>> cases = {
      {json{{"origin", {{"x", 1}}}}, "\"system\" is missing"},
      {json{{"system", "G60"}, {"origin", {{"x", 1}}}}, "one of G54 .. G59.3"},
      {json{{"system", 10}, {"origin", {{"x", 1}}}}, "\"system\" must be an integer from 1 to 9"},
      {json{{"system", "g54"}}, "give \"origin\" axis values or a \"rotation\""},
      {json{{"system", "G54"}, {"origin", {{"w", 1}}}}, "axis \"w\", which this machine lacks"},
      {json{{"system", "G54"}, {"rotation", 400}}, "\"rotation\" must be a number from -360"},
  };
  for (const auto& [params, message] : cases) {
    const json r = call("offsets.set", params);
    EXPECT_EQ(error_code(r), -32602) << params.dump();
    const std::string text = r["error"].value("message", "");
    EXPECT_NE(text.find(message), std::string::npos) << params.dump() << ": " << text;
  }
}

}  // namespace
}  // namespace cncd::test
