// Unit tests of size-limited file reading: regular files, the error of each kind of bad
// path, and inputs that never end (devices, a FIFO fed forever) stopping fast at the limit.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/file.hpp"

namespace plcfi::common {
namespace {

namespace fs = std::filesystem;

class FileRead : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("plcfi_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  fs::path dir_;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST_F(FileRead, ReadsRegularFilesWholeWithAnyBytes) {
  std::mt19937 rng(7);
  for (size_t size : {size_t{0}, size_t{1}, size_t{4095}, size_t{65536}, size_t{65537}, size_t{300'000}}) {
    std::string text(size, '\0');
    for (char& c : text) c = static_cast<char>(rng());
    const std::string path = write("f" + std::to_string(size), text);
    std::string got, err;
    ASSERT_TRUE(read_file(path, size == 0 ? 1 : size, &got, &err)) << err;
    EXPECT_EQ(got, text);
  }
}

TEST_F(FileRead, ErrorsNameThePathAndTheReason) {
  std::string text, err;
  const std::string missing = (dir_ / "nope.yaml").string();
  EXPECT_FALSE(read_file(missing, kMaxSpecBytes, &text, &err));
  EXPECT_EQ(err, missing + ": cannot open (No such file or directory)");
  EXPECT_FALSE(read_file(dir_.string(), kMaxSpecBytes, &text, &err));
  EXPECT_EQ(err, dir_.string() + ": is a directory");
  const std::string big = write("big", std::string(2000, 'x'));
  EXPECT_FALSE(read_file(big, 1000, &text, &err));
  EXPECT_EQ(err, big + ": is larger than 1000 bytes");
  EXPECT_TRUE(read_file(big, 2000, &text, &err)) << err;  // exactly at the limit is fine
  EXPECT_EQ(size_text(16 * kMiB), "16 MiB");
  EXPECT_EQ(size_text(kMiB + 1), "1048577 bytes");
}

TEST_F(FileRead, EndlessDevicesStopAtTheLimitWithinASecond) {
  for (const char* dev : {"/dev/zero", "/dev/urandom"}) {
    if (!fs::exists(dev)) GTEST_SKIP() << dev << " is missing";
    std::string text, err;
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_FALSE(read_file(dev, kMaxSpecBytes, &text, &err));
    EXPECT_EQ(err, std::string(dev) + ": is larger than 16 MiB");
    EXPECT_LT(seconds_since(t0), 1.0) << dev;
    EXPECT_TRUE(text.empty());
  }
}

TEST_F(FileRead, FifoFedForeverStopsAtTheLimit) {
  const std::string fifo = (dir_ / "endless").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // The reader stops and closes: the writer's next write fails (EPIPE), not a signal.
  auto old = std::signal(SIGPIPE, SIG_IGN);
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    const std::string chunk(4096, 'a');
    while (::write(fd, chunk.data(), chunk.size()) > 0) {
    }
    ::close(fd);
  });
  std::string text, err;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(read_file(fifo, kMiB, &text, &err));
  EXPECT_EQ(err, fifo + ": is larger than 1 MiB");
  EXPECT_LT(seconds_since(t0), 1.0);
  writer.join();
  std::signal(SIGPIPE, old);
}

TEST_F(FileRead, FifoWhoseWriterNeverWritesTimesOut) {
  const std::string fifo = (dir_ / "silent").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);  // holds the pipe open, writes nothing
    while (!done) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (fd >= 0) ::close(fd);
  });
  std::string text, err;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(read_file(fifo, kMiB, &text, &err, 200));
  EXPECT_EQ(err, fifo + ": no data for 200 ms (a pipe nobody writes to?)");
  EXPECT_LT(seconds_since(t0), 1.0);
  done = true;
  writer.join();
}

TEST_F(FileRead, FifoWithAFiniteWriterGivesItsText) {
  const std::string fifo = (dir_ / "finite").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string sent = "campaign: x\nprogram: y.st\n";
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    for (char c : sent) {  // byte by byte: the reader must wait for more, not stop early
      if (::write(fd, &c, 1) != 1) break;
    }
    ::close(fd);
  });
  std::string text, err;
  EXPECT_TRUE(read_file(fifo, kMiB, &text, &err)) << err;
  EXPECT_EQ(text, sent);
  writer.join();
}

}  // namespace
}  // namespace plcfi::common
