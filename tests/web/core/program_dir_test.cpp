// The program directory under attack: names, symlinks, FIFOs, interrupted and oversized
// uploads, the running program, a swapped directory. Judged by what is on disk afterwards.
#include "cncd/web/program_dir.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <set>
#include <thread>

#include "temp_dir.hpp"

namespace cncd::web {
namespace {

namespace fs = std::filesystem;

class ProgramDirTest : public test::TempDirTest, public ::testing::WithParamInterface<bool> {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    programs_ = dir_ / "programs";
    fs::create_directories(programs_);
    fs::create_directories(dir_ / "outside");
  }
  // Every name in `dir`, hidden ones too.
  static std::set<std::string> names(const fs::path& dir) {
    std::set<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
      out.insert(e.path().filename().string());
    return out;
  }
  ProgramDir open(std::int64_t max_bytes = 1 << 20) {
    ProgramDir dir(programs_, max_bytes);
    dir.set_use_tmpfile(GetParam());
    EXPECT_TRUE(dir.ok()) << dir.open_error();
    return dir;
  }
  static FileStatus upload(const ProgramDir& dir, const std::string& name,
                           const std::string& content, const fs::path& running = {}) {
    FileStatus status;
    auto up = dir.start_upload(status);
    if (!up) return status;
    status = up->write(content);
    if (!status.ok()) return status;
    return up->commit(name, running);
  }

  fs::path programs_;
};

TEST_P(ProgramDirTest, UploadListReadRenameDelete) {
  ProgramDir dir = open();
  ASSERT_TRUE(upload(dir, "b.ngc", "G0 X1\n").ok());
  ASSERT_TRUE(upload(dir, "a.nc", "").ok());
  write(programs_ / ".hidden", "x");
  fs::create_directories(programs_ / "subdir");
  fs::create_symlink("b.ngc", programs_ / "link.ngc");
  EXPECT_EQ(read(programs_ / "b.ngc"), "G0 X1\n");
  struct stat st {};
  ASSERT_EQ(::stat((programs_ / "b.ngc").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0077 & ~0044, 0u);  // at most readable by others, never writable

  FileStatus status;
  const auto list = dir.list(status);
  ASSERT_TRUE(list) << status.message;
  ASSERT_EQ(list->size(), 2u);  // no hidden file, directory or symlink
  EXPECT_EQ((*list)[0].name, "a.nc");
  EXPECT_EQ((*list)[0].size, 0);
  EXPECT_EQ((*list)[1].name, "b.ngc");
  EXPECT_EQ((*list)[1].size, 6);
  EXPECT_FALSE((*list)[1].estimate_s);
  const auto age = std::chrono::system_clock::now() - (*list)[1].mtime;
  EXPECT_LT(std::chrono::abs(age), std::chrono::hours(1));

  auto file = dir.open_for_read("b.ngc", status);
  ASSERT_TRUE(file) << status.message;
  EXPECT_EQ(file->size, 6);
  char buffer[16];
  EXPECT_EQ(::read(file->fd.get(), buffer, sizeof buffer), 6);

  EXPECT_EQ(dir.rename("b.ngc", "a.nc").error, FileError::exists);
  EXPECT_EQ(dir.rename("zz", "c.ngc").error, FileError::not_found);
  EXPECT_EQ(dir.rename("subdir", "c.ngc").error, FileError::not_regular);
  ASSERT_TRUE(dir.rename("b.ngc", "c.ngc").ok());
  EXPECT_EQ(read(programs_ / "c.ngc"), "G0 X1\n");
  EXPECT_EQ(dir.remove("b.ngc").error, FileError::not_found);
  EXPECT_EQ(dir.remove("subdir").error, FileError::not_regular);
  ASSERT_TRUE(dir.remove("c.ngc").ok());
  EXPECT_EQ(names(programs_), (std::set<std::string>{".hidden", "a.nc", "link.ngc", "subdir"}));

  ASSERT_TRUE(upload(dir, "a.nc", "replaced").ok());  // an upload replaces a program
  EXPECT_EQ(read(programs_ / "a.nc"), "replaced");
}

TEST_P(ProgramDirTest, BadNamesReachNothing) {
  ProgramDir dir = open();
  write(programs_ / "ok.ngc", "x");
  const std::string too_long(256, 'n');
  for (const std::string& name :
       {std::string("../x"), std::string("/tmp/x"), percent_decode("%2e%2e%2fx").text,
        std::string(".."), std::string(""), std::string("a\0b", 3), too_long, std::string(".x")}) {
    EXPECT_EQ(upload(dir, name, "evil").error, FileError::bad_name) << name;
    EXPECT_EQ(dir.rename("ok.ngc", name).error, FileError::bad_name) << name;
    EXPECT_EQ(dir.rename(name, "ok2.ngc").error, FileError::bad_name) << name;
    EXPECT_EQ(dir.remove(name).error, FileError::bad_name) << name;
    FileStatus status;
    EXPECT_FALSE(dir.open_for_read(name, status)) << name;
    EXPECT_EQ(status.error, FileError::bad_name) << name;
    EXPECT_FALSE(dir.resolve(name, status)) << name;
    EXPECT_EQ(status.error, FileError::bad_name) << name;
  }
  EXPECT_EQ(names(programs_), std::set<std::string>{"ok.ngc"});
  EXPECT_EQ(names(dir_), (std::set<std::string>{"outside", "programs"}));
  EXPECT_TRUE(upload(dir, std::string(255, 'n'), "long but fine").ok());
}

TEST_P(ProgramDirTest, SymlinksOutAreNeitherReadNorOpenedNorWrittenThrough) {
  write(dir_ / "outside/secret", "secret");
  ASSERT_EQ(::mkfifo((dir_ / "outside/fifo").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((programs_ / "fifo.ngc").c_str(), 0600), 0);
  fs::create_symlink(dir_ / "outside/secret", programs_ / "out.ngc");
  fs::create_symlink("../outside/secret", programs_ / "rel.ngc");
  fs::create_symlink(dir_ / "outside/fifo", programs_ / "pipe.ngc");
  fs::create_symlink("/dev/zero", programs_ / "dev.ngc");
  fs::create_symlink(dir_ / "outside", programs_ / "dir.ngc");
  write(programs_ / "real.ngc", "G0 X1");
  fs::create_symlink("real.ngc", programs_ / "alias.ngc");
  ProgramDir dir = open();
  FileStatus status;
  for (const std::string name :
       {"out.ngc", "rel.ngc", "pipe.ngc", "dev.ngc", "dir.ngc", "fifo.ngc", "alias.ngc"}) {
    EXPECT_FALSE(dir.open_for_read(name, status)) << name;  // and does not block on a FIFO
    EXPECT_EQ(status.error, FileError::not_regular) << name;
  }
  for (const std::string name : {"out.ngc", "rel.ngc", "pipe.ngc", "dev.ngc", "dir.ngc"}) {
    EXPECT_FALSE(dir.resolve(name, status)) << name;
    EXPECT_EQ(status.error, FileError::outside) << name << ": " << status.message;
  }
  EXPECT_FALSE(dir.resolve("fifo.ngc", status));
  EXPECT_EQ(status.error, FileError::not_regular);
  const auto resolved = dir.resolve("alias.ngc", status);  // a symlink inside stays inside
  ASSERT_TRUE(resolved) << status.message;
  EXPECT_EQ(*resolved, fs::canonical(programs_ / "real.ngc"));
  EXPECT_EQ(dir.resolve("none.ngc", status), std::nullopt);
  EXPECT_EQ(status.error, FileError::not_found);
  EXPECT_EQ(dir.rename("out.ngc", "x.ngc").error, FileError::not_regular);

  // An upload over a symlink replaces the link, never what it points to.
  ASSERT_TRUE(upload(dir, "out.ngc", "mine").ok());
  EXPECT_EQ(read(dir_ / "outside/secret"), "secret");
  EXPECT_FALSE(fs::is_symlink(programs_ / "out.ngc"));
  ASSERT_TRUE(dir.remove("rel.ngc").ok());  // deleting a link leaves its target
  EXPECT_EQ(read(dir_ / "outside/secret"), "secret");
  EXPECT_EQ(names(dir_ / "outside"), (std::set<std::string>{"fifo", "secret"}));
}

TEST_P(ProgramDirTest, AnInterruptedUploadLeavesNothing) {
  ProgramDir dir = open();
  {
    FileStatus status;
    auto up = dir.start_upload(status);
    ASSERT_TRUE(up) << status.message;
    ASSERT_TRUE(up->write(std::string(100000, 'x')).ok());
    EXPECT_EQ(up->size(), 100000);
    if (!GetParam()) {
      EXPECT_EQ(names(programs_).size(), 1u);  // the hidden file, while it lasts
    }
  }  // the connection dropped: destroyed without commit
  EXPECT_TRUE(names(programs_).empty());
  FileStatus status;
  auto up = dir.start_upload(status);
  ASSERT_TRUE(up->write("abc").ok());
  up->abort();
  EXPECT_TRUE(names(programs_).empty());
  EXPECT_EQ(up->commit("late.ngc").error, FileError::io);
  EXPECT_TRUE(names(programs_).empty());
}

TEST_P(ProgramDirTest, ATooLargeUploadLeavesNothingAndKeepsTheOldProgram) {
  ProgramDir dir = open(10);
  write(programs_ / "p.ngc", "old");
  FileStatus status;
  auto up = dir.start_upload(status);
  ASSERT_TRUE(up->write("123456").ok());
  EXPECT_TRUE(up->write("7890").ok());  // exactly the limit
  const FileStatus over = up->write("1");
  EXPECT_EQ(over.error, FileError::too_large);
  EXPECT_EQ(over.message, "the upload is larger than 10 bytes ([WEB] MAX_UPLOAD_MB)");
  EXPECT_EQ(up->commit("p.ngc").error, FileError::io);
  EXPECT_EQ(names(programs_), std::set<std::string>{"p.ngc"});
  EXPECT_EQ(read(programs_ / "p.ngc"), "old");
}

TEST_P(ProgramDirTest, TheRunningProgramIsNeverReplacedRenamedOrDeleted) {
  write(programs_ / "run.ngc", "running");
  write(programs_ / "other.ngc", "other");
  // The daemon may name it through another path to the same directory.
  fs::create_symlink(programs_, dir_ / "via");
  ProgramDir dir = open();
  for (const fs::path& running :
       {programs_ / "run.ngc", dir_ / "via/run.ngc", fs::path(programs_.string() + "/./run.ngc")}) {
    EXPECT_EQ(upload(dir, "run.ngc", "new", running).error, FileError::running) << running;
    EXPECT_EQ(dir.rename("run.ngc", "moved.ngc", running).error, FileError::running);
    EXPECT_EQ(dir.rename("other.ngc", "run.ngc", running).error, FileError::running);
    EXPECT_EQ(dir.remove("run.ngc", running).error, FileError::running);
    EXPECT_TRUE(dir.is_running("run.ngc", running));
    EXPECT_FALSE(dir.is_running("other.ngc", running));
  }
  EXPECT_EQ(read(programs_ / "run.ngc"), "running");
  EXPECT_EQ(names(programs_), (std::set<std::string>{"other.ngc", "run.ngc"}));
  // Another program may still be uploaded while it runs.
  EXPECT_TRUE(upload(dir, "other.ngc", "new", programs_ / "run.ngc").ok());
}

TEST_P(ProgramDirTest, ConcurrentUploadsOfOneNameLeaveOneWholeFile) {
  ProgramDir dir = open();
  const auto content = [](int writer) { return std::string(20000 + writer, 'a' + writer); };
  std::vector<std::thread> writers;
  for (int w = 0; w < 4; ++w) {
    writers.emplace_back([&, w] {
      for (int i = 0; i < 25; ++i) {
        FileStatus status;
        auto up = dir.start_upload(status);
        ASSERT_TRUE(up) << status.message;
        const std::string text = content(w);
        // In pieces, so that the writers interleave.
        for (std::size_t at = 0; at < text.size(); at += 4096) {
          ASSERT_TRUE(up->write(std::string_view(text).substr(at, 4096)).ok());
        }
        ASSERT_TRUE(up->commit("same.ngc").ok());
      }
    });
  }
  for (auto& t : writers)
    t.join();
  EXPECT_EQ(names(programs_), std::set<std::string>{"same.ngc"});
  const std::string final = read(programs_ / "same.ngc");
  bool whole = false;
  for (int w = 0; w < 4; ++w)
    whole = whole || final == content(w);
  EXPECT_TRUE(whole) << "a mix of uploads, " << final.size() << " bytes";
}

TEST_P(ProgramDirTest, ASwappedDirectoryPathDoesNotRedirectWrites) {
  ProgramDir dir = open();
  fs::rename(programs_, dir_ / "moved");
  fs::create_symlink(dir_ / "outside", programs_);
  ASSERT_TRUE(upload(dir, "p.ngc", "here").ok());
  EXPECT_EQ(read(dir_ / "moved/p.ngc"), "here");
  EXPECT_TRUE(names(dir_ / "outside").empty());
  FileStatus status;
  const auto resolved = dir.resolve("p.ngc", status);
  ASSERT_TRUE(resolved) << status.message;
  EXPECT_EQ(*resolved, fs::canonical(dir_ / "moved/p.ngc"));
}

TEST_P(ProgramDirTest, WhatACrashedUploadLeftIsRemovedAfterAnHour) {
  const auto old_time = fs::file_time_type::clock::now() - std::chrono::hours(2);
  for (const std::string name : {".cncd-upload-0011223344556677", ".cncd-upload-8899aabbccddeeff",
                                 ".other-hidden", "program.ngc"}) {
    write(programs_ / name, "x");
  }
  for (const std::string name : {".cncd-upload-0011223344556677", ".other-hidden", "program.ngc"}) {
    fs::last_write_time(programs_ / name, old_time);
  }
  ProgramDir dir = open();
  EXPECT_EQ(names(programs_), (std::set<std::string>{".cncd-upload-8899aabbccddeeff",
                                                     ".other-hidden", "program.ngc"}));
  EXPECT_EQ(dir.remove_stale_uploads(std::chrono::seconds(0)), 1);
  EXPECT_EQ(names(programs_), (std::set<std::string>{".other-hidden", "program.ngc"}));
}

TEST(ProgramDirOpenTest, AMissingDirectorySaysSo) {
  ProgramDir dir("/nonexistent/programs", 10);
  EXPECT_FALSE(dir.ok());
  EXPECT_EQ(dir.open_error(),
            "/nonexistent/programs: cannot open the program directory: No such file or directory");
  FileStatus status;
  EXPECT_FALSE(dir.list(status));
  EXPECT_EQ(status.error, FileError::io);
  EXPECT_FALSE(dir.start_upload(status));
}

INSTANTIATE_TEST_SUITE_P(TmpfileAndHiddenFile, ProgramDirTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param) {
                           return param.param ? "Tmpfile" : "HiddenFile";
                         });

}  // namespace
}  // namespace cncd::web
