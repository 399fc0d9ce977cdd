#include "common/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>

#include "common/exit_codes.h"

namespace recruit {
namespace file_atomic_file_test {

namespace fs = std::filesystem;

fs::path TempDir() {
  fs::path p = fs::temp_directory_path() / ("recruit_atomic_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

TEST(AtomicFile, CommitWritesContentsAndLeavesNoTemporary) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "out.csv").string();
  ASSERT_TRUE(WriteFileAtomically(path, "a,b\n1,2\n").ok());
  auto read = ReadFile(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(*read, "a,b\n1,2\n");
  int files = 0;
  for (auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, WithoutCommitNothingIsLeftBehind) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "half.csv").string();
  {
    AtomicFile f(path);
    ASSERT_TRUE(f.ok());
    f.stream() << "partial";
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(AtomicFile, UnwritableDirectoryGivesErrorNamingPath) {
  AtomicFile f("/nonexistent_dir_recruit/x.csv");
  EXPECT_FALSE(f.ok());
  EXPECT_NE(f.error().find("/nonexistent_dir_recruit/x.csv"), std::string::npos);
  EXPECT_FALSE(f.Commit().ok());
}

// Runs `body` in a forked child and returns its wait status.
template <class F>
int InChild(F body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    body();
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

TEST(AtomicFile, TemporaryFilesAreRemovedOnSigtermAndTheProcessDiesOfIt) {
  const fs::path dir = TempDir();
  for (int sig : {SIGTERM, SIGINT}) {
    const int status = InChild([&] {
      InstallTempFileCleanupOnSignals();
      AtomicFile a((dir / "a.csv").string());
      AtomicFile b((dir / "b.mp4").string(), std::ios::binary);
      a.stream() << "partial" << std::flush;
      b.stream() << "partial" << std::flush;
      if (!fs::exists(a.temp_path()) || !fs::exists(b.temp_path())) ::_exit(3);
      ::raise(sig);
      ::_exit(4);  // not reached: the handler re-raises with the default action
    });
    ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_TRUE(fs::is_empty(dir)) << "a temporary file survived signal " << sig;
  }
  fs::remove_all(dir);
}

TEST(AtomicFile, CommittedFilesAreNotTouchedBySignalCleanup) {
  const fs::path dir = TempDir();
  const int status = InChild([&] {
    InstallTempFileCleanupOnSignals();
    if (!WriteFileAtomically((dir / "done.json").string(), "{}").ok()) ::_exit(3);
    ::raise(SIGTERM);
  });
  EXPECT_TRUE(WIFSIGNALED(status));
  EXPECT_TRUE(fs::exists(dir / "done.json"));
  fs::remove_all(dir);
}

TEST(AtomicFile, AFullDiskIsAnErrorAndLeavesNoFile) {
  // RLIMIT_FSIZE makes writes past the limit fail (EFBIG), as a full disk does.
  const fs::path dir = TempDir();
  const std::string path = (dir / "big.csv").string();
  const int status = InChild([&] {
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim{1000, 1000};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    Status s = WriteFileAtomically(path, std::string(100000, 'x'));
    if (s.ok()) ::_exit(3);
    if (s.error().find("cannot write") == std::string::npos) ::_exit(4);
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: the write reported success; 4: unclear message";
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

// The class of a failed read is CodeOf's (common/result.h), as the CLI's exit codes say
// (docs/reliability.md): a path that names no file is bad input (3), a file that is there but
// cannot be opened is an I/O failure (4).
TEST(ReadFile, AMissingFileIsBadInputAndAnUnopenableOneIo) {
  for (const std::string missing : {"/no/such/file.json", "/proc/self/status/not_a_dir"}) {
    SCOPED_TRACE(missing);
    auto r = ReadFile(missing);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find(missing), std::string::npos);
    EXPECT_EQ(exit_code::Of(r.failure()), exit_code::kBadInput);
    EXPECT_EQ(r.code(), CodeOf(std::error_code(ENOENT, std::generic_category())));
  }
  // A socket is there (stat succeeds) but cannot be opened, even by root.
  const fs::path dir = TempDir();
  const std::string sock = (dir / "s").string();
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(sock.size(), sizeof(addr.sun_path));
  std::memcpy(addr.sun_path, sock.c_str(), sock.size() + 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
  auto r = ReadFile(sock);
  ::close(fd);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("cannot open '" + sock + "'"), std::string::npos) << r.error();
  EXPECT_EQ(exit_code::Of(r.failure()), exit_code::kIo);
  EXPECT_EQ(r.code(), CodeOf(std::error_code(ENXIO, std::generic_category())));
  fs::remove_all(dir);
}

}  // namespace file_atomic_file_test
}  // namespace recruit
