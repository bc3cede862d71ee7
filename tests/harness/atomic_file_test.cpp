// Reports are replaced whole or not at all.

#include "harness/atomic_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/harness/scratch_dir.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;

class AtomicFile : public ::testing::Test {
 protected:
  static std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  std::size_t files_in_dir() const {
    return static_cast<std::size_t>(
        std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  test::ScratchDir scratch_{"hil-atomic"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(AtomicFile, WritesTheBytesExactlyAndLeavesNoTemporaryFile) {
  const fs::path target = dir_ / "hil.xml";
  std::string bytes = "<testsuites>\n";
  bytes.push_back('\0');  // binary-safe
  bytes += std::string(100000, 'x');
  write_file_atomically(target.string(), bytes);
  EXPECT_EQ(read(target), bytes);
  EXPECT_EQ(files_in_dir(), 1u);
  struct stat st {};
  ASSERT_EQ(::stat(target.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);  // readable by CI, not 0600 like a temp file
}

TEST_F(AtomicFile, ReplacesAnExistingFileWholeAndKeepsItsMode) {
  const fs::path target = dir_ / "hil.xml";
  std::ofstream(target) << "old report that is longer than the new one";
  fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write_file_atomically(target.string(), "new");
  EXPECT_EQ(read(target), "new");
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  EXPECT_EQ(files_in_dir(), 1u);
}

TEST_F(AtomicFile, AFailedRenameNamesThePathAndLeavesNothingBehind) {
  // A folder where the report should go: the rename cannot replace it
  // (this fails for root too, unlike a permission).
  const fs::path target = dir_ / "hil.xml";
  fs::create_directories(target);
  std::ofstream(target / "kept") << "old";
  try {
    write_file_atomically(target.string(), "new");
    FAIL() << "wrote";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write " + target.string() + ": rename"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(read(target / "kept"), "old");
  EXPECT_EQ(files_in_dir(), 1u);  // the temporary file is gone
}

TEST_F(AtomicFile, AMissingFolderIsAnError) {
  EXPECT_THROW(write_file_atomically((dir_ / "no" / "such" / "hil.xml").string(), "x"),
               std::runtime_error);
}

TEST_F(AtomicFile, APlainFileNameGoesToTheCurrentFolder) {
  const auto cwd = fs::current_path();
  fs::current_path(dir_);
  write_file_atomically("plain.xml", "x");
  fs::current_path(cwd);
  EXPECT_EQ(read(dir_ / "plain.xml"), "x");
}

}  // namespace
}  // namespace hil::harness
