// program.open reads programs from the program directories only ([DISPLAY] PROGRAM_PREFIX,
// [CNCD] PROGRAM_DIRS; the test machine has the source tree's examples/ and its own
// directory), symlinks resolved; a path outside gets one message whether it exists or not.
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

const std::string kExamples = std::string(CNCD_SOURCE_DIR) + "/examples";

class ProgramDirsTest : public MachineTest {
 protected:
  // The error message of an open of `path`, with `path` itself written as PATH.
  std::string refusal(const std::string& path) {
    const json r = call("program.open", {{"path", path}});
    EXPECT_EQ(error_code(r), 1003) << path << ": " << r.dump();
    std::string message = r.contains("error") ? r["error"].value("message", "") : "";
    if (const auto at = message.find(path); at != std::string::npos)
      message.replace(at, path.size(), "PATH");
    return message;
  }
};

TEST_F(ProgramDirsTest, EveryPathOutsideGetsTheSameMessage) {
  TempDir elsewhere;
  const auto valid = elsewhere.write("part.ngc", "G21 G90\nG0 X1\nM2\n");
  fs::create_symlink("/etc/passwd", dir_.path() / "passwd.ngc");
  fs::create_symlink("/etc", dir_.path() / "etc");
  fs::create_symlink(valid, dir_.path() / "part.ngc");
  const std::string expected = refusal("/etc/shadow");
  EXPECT_NE(expected.find("programs open only from the program directories"), std::string::npos)
      << expected;
  for (const std::string& path :
       {std::string("/etc/passwd"), std::string("/etc/no-such-file.ngc"),
        std::string("/no/such/dir/x.ngc"), valid.string(), (dir_.path() / "passwd.ngc").string(),
        (dir_.path() / "etc/shadow").string(), (dir_.path() / "etc/no-such-file").string(),
        (dir_.path() / "part.ngc").string(), dir_.path().string() + "/../" + valid.string(),
        dir_.path().string() + "/no-such-dir/../../../etc/passwd",
        std::string("../../etc/passwd")}) {
    EXPECT_EQ(refusal(path), expected) << path;
  }
  EXPECT_EQ(status()["program"]["path"], "");
}

TEST_F(ProgramDirsTest, APathWithANulByteIsRefused) {
  const auto program = dir_.write("part.ngc", "G21 G90\nG0 X1\nM2\n");
  const json r = call("program.open", {{"path", program.string() + std::string(1, '\0') + "x"}});
  EXPECT_EQ(error_code(r), -32602) << r.dump();
  EXPECT_NE(r["error"].value("message", "").find("NUL"), std::string::npos) << r.dump();
}

TEST_F(ProgramDirsTest, TextThatIsNotGcodeIsRefusedAtItsFirstLine) {
  const auto copy = dir_.write("accounts.ngc",
                               "root:x:0:0:root:/root:/bin/bash\n"
                               "daemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n");
  const json r = call("program.open", {{"path", copy.string()}});
  EXPECT_EQ(error_code(r), 1003) << r.dump();
  EXPECT_EQ(r["error"].value("message", "").rfind(copy.string() + ":1:", 0), 0u) << r.dump();
}

TEST_F(ProgramDirsTest, InsideTheDirectoriesTheErrorSaysWhatIsWrong) {
  fs::create_directory(dir_.path() / "sub");
  const json missing = call("program.open", {{"path", (dir_.path() / "gone.ngc").string()}});
  EXPECT_EQ(error_code(missing), 1003);
  EXPECT_NE(missing["error"].value("message", "").find("No such file"), std::string::npos)
      << missing.dump();
  const json directory = call("program.open", {{"path", (dir_.path() / "sub").string()}});
  EXPECT_NE(directory["error"].value("message", "").find("not a regular file"), std::string::npos)
      << directory.dump();
}

TEST_F(ProgramDirsTest, SubdirectoriesSymlinksWithinAndRelativePathsOpen) {
  fs::create_directory(dir_.path() / "jobs");
  const auto program = dir_.write("jobs/part.ngc", "G21 G90\nG0 X1\nM2\n");
  fs::create_symlink(program, dir_.path() / "latest.ngc");
  // The file itself, symlinks resolved.
  EXPECT_EQ(
      result_of(call("program.open", {{"path", (dir_.path() / "latest.ngc").string()}}))["path"],
      program.string());
  EXPECT_EQ(status()["program"]["path"], program.string());
  // Relative to the first program directory, [DISPLAY] PROGRAM_PREFIX.
  const std::string seed = fs::canonical(kExamples + "/g81_example1.ngc").string();
  EXPECT_EQ(result_of(call("program.open", {{"path", "g81_example1.ngc"}}))["path"], seed);
}

TEST_F(ProgramDirsTest, RunChecksThePathAgain) {
  ready_machine();
  const auto program = dir_.write("part.ngc", "G21 G90\nG0 X1\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  // Replaced by a symlink leading out of the directories after it was opened.
  TempDir elsewhere;
  const auto outside = elsewhere.write("other.ngc", "G21 G90\nG0 X2\nM2\n");
  fs::remove(program);
  fs::create_symlink(outside, program);
  const json r = call("program.run");
  EXPECT_EQ(error_code(r), 1003) << r.dump();
  EXPECT_NE(r["error"].value("message", "").find("program directories"), std::string::npos)
      << r.dump();
  EXPECT_EQ(status()["exec"], "idle");
}

// Without [DISPLAY] PROGRAM_PREFIX or [CNCD] PROGRAM_DIRS programs open from the INI's own
// directory only.
TEST(ProgramDirsDefaultTest, TheIniDirectoryWhenNeitherKeyIsGiven) {
  TempDir dir;
  copy_example_machine(dir.path());
  std::stringstream text;
  text << std::ifstream(dir.path() / "sim_mm.ini").rdbuf();
  std::string ini;
  for (std::string line; std::getline(text, line);) {
    if (line.starts_with("PROGRAM_PREFIX") || line.starts_with("PROGRAM_DIRS")) continue;
    ini += line + "\n";
  }
  const auto ini_path = dir.write("machine.ini", ini);
  const auto beside = dir.write("part.ngc", "G21 G90\nG0 X1\nM2\n");
  DaemonProcess daemon;
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", ini_path.string()}), "");
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon.socket()), "");
  EXPECT_EQ(result_of(client.call("program.open", {{"path", beside.string()}}))["path"],
            beside.string());
  const json r = client.call("program.open", {{"path", kExamples + "/g81_example1.ngc"}});
  EXPECT_EQ(error_code(r), 1003) << r.dump();
  EXPECT_NE(r["error"].value("message", "").find("(" + dir.path().string() + ")"),
            std::string::npos)
      << r.dump();
  EXPECT_NE(daemon.log().find("programs open from " + dir.path().string()), std::string::npos)
      << daemon.log();
}

}  // namespace
}  // namespace cncd::test
