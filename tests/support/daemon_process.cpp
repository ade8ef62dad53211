#include "daemon_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace cncd::test {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

namespace {

int decode_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

pid_t spawn(const std::vector<std::string>& argv, const std::filesystem::path& out,
            const std::filesystem::path& err, int stdin_fd = -1) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  const int in_fd = stdin_fd >= 0 ? stdin_fd : open("/dev/null", O_RDONLY);
  const int out_fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int err_fd = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (in_fd < 0 || out_fd < 0 || err_fd < 0) _exit(127);
  dup2(in_fd, STDIN_FILENO);
  dup2(out_fd, STDOUT_FILENO);
  dup2(err_fd, STDERR_FILENO);
  std::vector<char*> args;
  for (const auto& a : argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execv(args[0], args.data());
  _exit(127);
}

bool socket_accepts(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const bool ok = connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  close(fd);
  return ok;
}

}  // namespace

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "cncd-test-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + pattern);
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path TempDir::write(const std::string& name, const std::string& content) const {
  const auto file = path_ / name;
  std::ofstream(file, std::ios::binary) << content;
  return file;
}

std::filesystem::path copy_example_machine(const std::filesystem::path& dir,
                                           const std::string& name) {
  const std::filesystem::path examples = std::filesystem::path(CNCD_SOURCE_DIR) / "config/examples";
  for (const auto& entry : std::filesystem::directory_iterator(examples)) {
    if (entry.path().stem() != name) continue;
    if (entry.path().extension() == ".ini") {
      std::ofstream(dir / entry.path().filename(), std::ios::trunc)
          << relocate_example_ini(slurp(entry.path()));
    } else {
      std::filesystem::copy_file(entry.path(), dir / entry.path().filename(),
                                 std::filesystem::copy_options::overwrite_existing);
    }
  }
  return dir / (name + ".ini");
}

std::string relocate_example_ini(std::string text) {
  const std::string prefix = "PROGRAM_PREFIX = ../../examples";
  if (const auto at = text.find(prefix); at != std::string::npos) {
    text.replace(at, prefix.size(), "PROGRAM_PREFIX = " CNCD_SOURCE_DIR "/examples");
  }
  const std::string section = "[CNCD]\n";
  if (const auto at = text.find(section); at != std::string::npos) {
    text.insert(at + section.size(), "PROGRAM_DIRS = .\n");
  } else {
    text += "\n[CNCD]\nPROGRAM_DIRS = .\n";
  }
  return text;
}

CommandResult run_command(const std::vector<std::string>& argv) {
  TempDir dir;
  const pid_t pid = spawn(argv, dir.path() / "out", dir.path() / "err");
  int status = 0;
  waitpid(pid, &status, 0);
  return {decode_status(status), slurp(dir.path() / "out"), slurp(dir.path() / "err")};
}

BackgroundCommand::BackgroundCommand(const std::vector<std::string>& argv) {
  int fds[2];
  if (pipe(fds) != 0) return;
  pid_ = spawn(argv, dir_.path() / "out", dir_.path() / "err", fds[0]);
  close(fds[0]);
  stdin_fd_ = fds[1];
}

BackgroundCommand::~BackgroundCommand() {
  if (stdin_fd_ >= 0) close(stdin_fd_);
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

bool BackgroundCommand::write_stdin(const std::string& text) {
  return stdin_fd_ >= 0 &&
         write(stdin_fd_, text.data(), text.size()) == static_cast<ssize_t>(text.size());
}

std::string BackgroundCommand::err_so_far() const {
  return slurp(dir_.path() / "err");
}

CommandResult BackgroundCommand::wait() {
  if (stdin_fd_ >= 0) {
    close(stdin_fd_);
    stdin_fd_ = -1;
  }
  int status = 0;
  if (pid_ > 0) waitpid(pid_, &status, 0);
  pid_ = -1;
  return {decode_status(status), slurp(dir_.path() / "out"), slurp(dir_.path() / "err")};
}

DaemonProcess::~DaemonProcess() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

std::string DaemonProcess::start(const std::filesystem::path& dir,
                                 const std::vector<std::string>& args) {
  socket_ = (dir / "cncd.sock").string();
  log_ = dir / "cncd.log";
  std::vector<std::string> argv{CNCD_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  // State files stay in the test's own directory, never in a state directory shared by runs.
  if (!default_state_dir_ && std::find(args.begin(), args.end(), "--state-dir") == args.end()) {
    argv.push_back("--state-dir");
    argv.push_back(dir.string());
  }
  argv.push_back("--socket");
  argv.push_back(socket_);
  pid_ = spawn(argv, dir / "cncd.out", log_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return "cncd exited with status " + std::to_string(decode_status(status)) + ":\n" + log();
    }
    if (socket_accepts(socket_)) return "";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return "cncd did not open its socket within 20 s:\n" + log();
}

int DaemonProcess::stop() {
  return end_with(SIGTERM);
}

int DaemonProcess::end_with(int signal) {
  if (pid_ <= 0) return -1;
  kill(pid_, signal);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return decode_status(status);
}

int DaemonProcess::stop_within(int limit_ms) {
  if (pid_ <= 0) return -1;
  kill(pid_, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(limit_ms);
  int status = 0;
  while (waitpid(pid_, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      end_with(SIGKILL);
      return -2;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  pid_ = -1;
  return decode_status(status);
}

void DaemonProcess::signal(int signal) {
  if (pid_ > 0) kill(pid_, signal);
}

int DaemonProcess::kill_hard() {
  return end_with(SIGKILL);
}

std::string DaemonProcess::log() const {
  return slurp(log_);
}

}  // namespace cncd::test
