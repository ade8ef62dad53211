// The parameter file ([RS274NGC] PARAMETER_FILE) is recognised before it is used: every line
// is a "NUMBER VALUE" pair (blank lines aside), numbers increase, values are finite and within
// the bound. Anything else (a mistyped path to the tool table, the INI, /etc/passwd) is refused
// with file and line, and a refused file is never written over.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

namespace fs = std::filesystem;

class ParameterFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("cncd_var_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& text) {
    const fs::path path = dir_ / "machine.var";
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  static std::string slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // The load error of an interpreter reading `path`, as the daemon prints it, or "".
  static std::string load_error(const fs::path& path) {
    InterpOptions options;
    options.parameter_file = path;
    const Interpreter interp(options);
    return interp.load_error() ? interp.load_error()->message : "";
  }
  std::string error_for(const std::string& text) { return load_error(write(text)); }

  fs::path dir_;
};

TEST_F(ParameterFile, LinesThatAreNotNumberValuePairsAreRefusedWithTheirLine) {
  const std::string passwd =
      "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n";
  const fs::path path = write(passwd);
  EXPECT_EQ(load_error(path), path.string() +
                                  ":1: 'root:x:0:0:root:/root:/bin/bash' is not a parameter line "
                                  "(NUMBER VALUE): is this a parameter file?");
  EXPECT_EQ(slurp(path), passwd);

  const std::string tool_table = "T1 P1 Z+0.511 D0.125 ;1/8 end mill\n";
  EXPECT_NE(error_for(tool_table).find("machine.var:1: 'T1 P1 Z+0.511"), std::string::npos);
  const std::string ini = "[EMC]\nVERSION = 1.1\n";
  EXPECT_NE(error_for(ini).find("machine.var:1: '[EMC]'"), std::string::npos);
  // One bad line among good ones.
  EXPECT_NE(error_for("5220\t1.000000\n5221 1 # G54 X\n")
                .find("machine.var:2: '5221 1 # G54 X' is not a parameter line"),
            std::string::npos);
  EXPECT_NE(error_for("5220\t1.000000\n# offsets\n").find("machine.var:2: '# offsets'"),
            std::string::npos);
  EXPECT_NE(error_for("5221\n").find("machine.var:1: '5221' is not a parameter line"),
            std::string::npos);
  EXPECT_NE(error_for("5221.5 1\n").find("machine.var:1:"), std::string::npos);
  EXPECT_NE(error_for("5221 0x10\n").find("machine.var:1:"), std::string::npos);
  EXPECT_NE(error_for(std::string("5221 1\n\0\n", 9)).find("machine.var:2:"), std::string::npos);
}

TEST_F(ParameterFile, NumbersOutOfRangeRepeatedOrOutOfOrderAreRefused) {
  EXPECT_NE(error_for("0 1\n").find("machine.var:1: parameter number 0 is out of range (1-5601)"),
            std::string::npos)
      << error_for("0 1\n");
  EXPECT_NE(error_for("5602 1\n").find("machine.var:1: parameter number 5602 is out of range"),
            std::string::npos);
  EXPECT_NE(error_for("5220 1\n5221 1\n5221 2\n")
                .find("machine.var:3: parameter 5221 is given twice (first on line 2)"),
            std::string::npos)
      << error_for("5220 1\n5221 1\n5221 2\n");
  EXPECT_NE(error_for("5221 1\n5220 1\n")
                .find("machine.var:2: parameter 5220 comes after 5221: the numbers must increase"),
            std::string::npos)
      << error_for("5221 1\n5220 1\n");
}

TEST_F(ParameterFile, ValuesThatAreNotFiniteOrTooLargeAreRefusedWithTheValue) {
  for (const char* value :
       {"nan", "-nan", "inf", "-inf", "infinity", "1e400", "1e300", "1000000001", "-2e9"}) {
    SCOPED_TRACE(value);
    const std::string error = error_for(std::string("5220 1\n5221 ") + value + "\n");
    EXPECT_NE(error.find(std::string("machine.var:2: parameter 5221: value '") + value + "'"),
              std::string::npos)
        << error;
  }
  EXPECT_NE(error_for("5221 1e400\n").find("is not a finite number"), std::string::npos);
  EXPECT_NE(error_for("5221 1e300\n").find("is out of range (at most 1e9 in size)"),
            std::string::npos);
}

TEST_F(ParameterFile, ARefusedFileIsNeverWrittenOver) {
  const std::string passwd = "root:x:0:0:root:/root:/bin/bash\n";
  const fs::path path = write(passwd);
  InterpOptions options;
  options.parameter_file = path;
  Interpreter interp(options);
  ASSERT_TRUE(interp.load_error().has_value());
  const auto saved = interp.save_parameters();
  ASSERT_TRUE(saved.has_value());
  EXPECT_NE(saved->message.find("not written"), std::string::npos) << saved->message;
  EXPECT_EQ(slurp(path), passwd);
  // No temporary file left beside it either.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(ParameterFile, TheFormatsLinuxCncWritesAndHandEditsOfThemAreRead) {
  const fs::path data = CNCD_VAR_FILES_DIR;
  struct Case {
    const char* file;
    int coord_system;
    double g54_x;
    double g55_x;
  };
  for (const Case& c :
       {Case{"linuxcnc_written.var", 1, 12.5, 100.0}, Case{"crlf.var", 2, 0.0, -7.5},
        Case{"hand_edited.var", 2, 1.5, 1e9}, Case{"empty.var", 1, 0.0, 0.0}}) {
    SCOPED_TRACE(c.file);
    const fs::path copy = dir_ / c.file;
    fs::copy_file(data / c.file, copy, fs::copy_options::overwrite_existing);
    InterpOptions options;
    options.parameter_file = copy;
    Interpreter interp(options);
    ASSERT_FALSE(interp.load_error()) << interp.load_error()->to_string();
    EXPECT_EQ(interp.state().coord_system, c.coord_system);
    EXPECT_EQ(interp.coord_system_origin(1)[0], c.g54_x);
    EXPECT_EQ(interp.coord_system_origin(2)[0], c.g55_x);
    // What the interpreter writes, it reads again.
    ASSERT_FALSE(interp.save_parameters());
    InterpOptions again;
    again.parameter_file = copy;
    const Interpreter reread(again);
    EXPECT_FALSE(reread.load_error()) << reread.load_error()->to_string();
    EXPECT_EQ(reread.coord_system_origin(2)[0], c.g55_x);
  }
  const Interpreter g54_rotation([&] {
    InterpOptions options;
    options.parameter_file = data / "linuxcnc_written.var";
    return options;
  }());
  double rotation = 0;
  EXPECT_EQ(g54_rotation.coord_system_origin(1, &rotation)[1], -3.25);
  EXPECT_EQ(rotation, 15.0);
}

TEST_F(ParameterFile, SomethingThatIsNotAFileIsRefused) {
  const fs::path sub = dir_ / "a_directory";
  fs::create_directories(sub);
  EXPECT_NE(load_error(sub).find("is not a regular file"), std::string::npos) << load_error(sub);
}

}  // namespace
}  // namespace cncd::interp
