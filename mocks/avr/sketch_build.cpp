// Building a sketch: check the toolchain, hash the inputs, look in the
// cache, else write a build folder (the generated .cpp, the sketch's other
// sources, a Makefile for arduino-mk) and run make in it, then move the ELF
// into the cache in one rename.

#include "mocks/avr/sketch_build.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <system_error>
#include <thread>

extern char** environ;

namespace hil::mocks::avr {

// This file's own namespace: hil's unity builds compile all of hil::mocks as
// one source, where two files' anonymous namespaces are one.
namespace sketch_build_impl {

namespace fs = std::filesystem;
using Kind = SketchBuildError::Kind;

namespace {

// Part of every cache key: bump when the generated sources or the Makefile
// change in a way the key does not otherwise see.
constexpr std::string_view kBuilderVersion = "hil sketch build 1";

constexpr std::string_view kInstallHint =
    ": install gcc-avr avr-libc arduino-core-avr arduino-mk (ci/install-deps.sh does)";

// ---------------------------------------------------------------- SHA-256

class Sha256 {
 public:
  void update(std::string_view bytes) {
    for (const char c : bytes) {
      block_[fill_++] = static_cast<std::uint8_t>(c);
      if (fill_ == 64) {
        compress();
        fill_ = 0;
      }
    }
    length_bytes_ += bytes.size();
  }

  std::string hex() {
    const std::uint64_t bits = length_bytes_ * 8;
    update(std::string_view("\x80", 1));
    while (fill_ != 56)
      update(std::string_view("\0", 1));
    for (int i = 7; i >= 0; --i)
      block_[fill_++] = static_cast<std::uint8_t>(bits >> (8 * i));
    compress();
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string out;
    for (const std::uint32_t word : state_) {
      for (int i = 28; i >= 0; i -= 4)
        out += kDigits[(word >> i) & 0xF];
    }
    return out;
  }

 private:
  static std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

  void compress() {
    static constexpr std::array<std::uint32_t, 64> kRound = {
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
        0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
        0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
        0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
        0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
        0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
        0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
        0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
        0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
        0xc67178f2};
    std::array<std::uint32_t, 64> w{};
    for (std::size_t i = 0; i < 16; ++i) {
      w[i] = (std::uint32_t{block_[4 * i]} << 24) | (std::uint32_t{block_[4 * i + 1]} << 16) |
             (std::uint32_t{block_[4 * i + 2]} << 8) | std::uint32_t{block_[4 * i + 3]};
    }
    for (std::size_t i = 16; i < 64; ++i) {
      const std::uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const std::uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    auto v = state_;
    for (std::size_t i = 0; i < 64; ++i) {
      const std::uint32_t s1 = rotr(v[4], 6) ^ rotr(v[4], 11) ^ rotr(v[4], 25);
      const std::uint32_t choose = (v[4] & v[5]) ^ (~v[4] & v[6]);
      const std::uint32_t t1 = v[7] + s1 + choose + kRound[i] + w[i];
      const std::uint32_t s0 = rotr(v[0], 2) ^ rotr(v[0], 13) ^ rotr(v[0], 22);
      const std::uint32_t majority = (v[0] & v[1]) ^ (v[0] & v[2]) ^ (v[1] & v[2]);
      const std::uint32_t t2 = s0 + majority;
      v = {t1 + t2, v[0], v[1], v[2], v[3] + t1, v[4], v[5], v[6]};
    }
    for (std::size_t i = 0; i < 8; ++i)
      state_[i] += v[i];
  }

  std::array<std::uint32_t, 8> state_ = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                         0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::array<std::uint8_t, 64> block_{};
  std::size_t fill_ = 0;
  std::uint64_t length_bytes_ = 0;
};

// ---------------------------------------------------------------- files

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SketchBuildError(Kind::kIo, "cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_file(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw SketchBuildError(Kind::kIo, "cannot write " + path.string());
}

/// Copies `from` over `to` so that a reader of `to` sees the old file or
/// the whole new one: a temporary file beside `to`, flushed, then renamed.
void copy_atomically(const fs::path& from, const fs::path& to) {
  const std::string bytes = read_file(from);
  const fs::path folder = to.parent_path().empty() ? fs::path(".") : to.parent_path();
  std::string tmp = (folder / ("." + to.filename().string() + ".XXXXXX")).string();
  const int fd = mkstemp(tmp.data());
  if (fd < 0) {
    throw SketchBuildError(Kind::kIo, "cannot write " + to.string() + ": " + std::strerror(errno));
  }
  std::size_t done = 0;
  bool ok = true;
  while (ok && done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  ok = ok && ::fchmod(fd, 0644) == 0 && ::fsync(fd) == 0;
  const int saved = errno;
  ::close(fd);
  if (!ok || std::rename(tmp.c_str(), to.c_str()) != 0) {
    const int err = ok ? errno : saved;
    ::unlink(tmp.c_str());
    throw SketchBuildError(Kind::kIo, "cannot write " + to.string() + ": " + std::strerror(err));
  }
}

/// Removes a build folder on every way out of build_sketch.
class TempDir {
 public:
  explicit TempDir(const fs::path& parent) {
    std::string pattern = (parent / ".build-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw SketchBuildError(Kind::kIo, "cannot make a build folder in " + parent.string() + ": " +
                                            std::strerror(errno));
    }
    path_ = pattern;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// ---------------------------------------------------------------- processes

struct ProcessResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr as they came
};

/// Runs `argv` (argv[0] a path, no shell) with `env`, stdin from /dev/null,
/// and collects what it prints.
ProcessResult run_process(const std::vector<std::string>& argv,
                          const std::vector<std::string>& env) {
  std::vector<char*> args;
  for (const auto& a : argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<char*> envp;
  for (const auto& e : env)
    envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);

  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    throw SketchBuildError(Kind::kIo, std::string("cannot make a pipe: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  // No other descriptor of this process reaches the tools (a pipe held
  // open there would keep another reader from its end of file).
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (spawned != 0) {
    ::close(pipe_fds[0]);
    throw SketchBuildError(Kind::kToolchain,
                           "cannot run " + argv[0] + ": " + std::strerror(spawned));
  }
  ProcessResult result;
  std::array<char, 4096> buf{};
  for (;;) {
    const ssize_t n = ::read(pipe_fds[0], buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    result.output.append(buf.data(), static_cast<std::size_t>(n));
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

/// This process's environment for the build: messages in plain English
/// (LC_ALL=C), and no make settings inherited from a build that runs hil.
std::vector<std::string> build_environment() {
  std::vector<std::string> env;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string_view entry = *e;
    const std::string_view name = entry.substr(0, entry.find('='));
    if (name == "MAKEFLAGS" || name == "MFLAGS" || name == "MAKELEVEL" || name == "MAKEFILES" ||
        name == "LC_ALL" || name == "GCC_COLORS")
      continue;
    env.emplace_back(entry);
  }
  env.emplace_back("LC_ALL=C");
  return env;
}

std::optional<fs::path> find_in_path(std::string_view program) {
  const char* path = std::getenv("PATH");
  std::string_view dirs = path != nullptr ? path : "/usr/bin:/bin";
  while (!dirs.empty()) {
    const std::size_t colon = dirs.find(':');
    const std::string_view dir = dirs.substr(0, colon);
    dirs = colon == std::string_view::npos ? std::string_view{} : dirs.substr(colon + 1);
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------- the sketch

/// Names make and the shell under it take as they are.
bool is_plain_name(std::string_view name) {
  return !name.empty() && name[0] != '-' && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.' ||
           c == '+';
  });
}

bool is_plain_path(const fs::path& path) {
  const std::string s = path.string();
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.' ||
           c == '+' || c == '/';
  });
}

struct SourceFile {
  fs::path path;  ///< absolute
  std::string name;
  std::string bytes;
};

struct Sketch {
  fs::path ino;                     ///< absolute
  std::vector<SourceFile> sources;  ///< the folder's sources, by name; the .ino files first
};

bool is_source(const fs::path& p) {
  static const std::array<std::string_view, 6> kExtensions = {".ino", ".cpp", ".c",
                                                              ".S",   ".h",   ".hpp"};
  const std::string ext = p.extension().string();
  return std::find(kExtensions.begin(), kExtensions.end(), ext) != kExtensions.end();
}

Sketch read_sketch(const fs::path& ino_arg) {
  std::error_code ec;
  if (ino_arg.extension() != ".ino") {
    throw SketchBuildError(Kind::kSketch,
                           ino_arg.string() + ": not a sketch (an Arduino sketch is a .ino file)");
  }
  if (!fs::is_regular_file(ino_arg, ec)) {
    throw SketchBuildError(Kind::kSketch, ino_arg.string() + ": no such sketch file");
  }
  Sketch sketch;
  sketch.ino = fs::weakly_canonical(fs::absolute(ino_arg), ec);
  if (ec) sketch.ino = fs::absolute(ino_arg);
  std::vector<fs::path> paths;
  for (const auto& entry : fs::directory_iterator(sketch.ino.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(".") && is_source(entry.path()) && entry.is_regular_file(ec))
      paths.push_back(entry.path());
  }
  if (ec) {
    throw SketchBuildError(Kind::kSketch, sketch.ino.parent_path().string() +
                                              ": cannot list the sketch folder: " + ec.message());
  }
  // The main .ino first, the folder's other .ino files after it by name (as
  // the Arduino IDE joins them), then the other sources by name.
  std::sort(paths.begin(), paths.end(), [&](const fs::path& a, const fs::path& b) {
    auto rank = [&](const fs::path& p) {
      return p.filename() == sketch.ino.filename() ? 0 : p.extension() == ".ino" ? 1 : 2;
    };
    return std::pair(rank(a), a.filename().string()) < std::pair(rank(b), b.filename().string());
  });
  for (const auto& p : paths) {
    const std::string name = p.filename().string();
    if (!is_plain_name(name)) {
      throw SketchBuildError(Kind::kSketch,
                             p.string() +
                                 ": a sketch's file names may hold only letters, digits and "
                                 "'_' '-' '.' '+' (arduino-mk hands them to the shell)");
    }
    sketch.sources.push_back({p, name, read_file(p)});
  }
  return sketch;
}

// ---------------------------------------------------------------- the toolchain

struct Toolchain {
  fs::path bin;      ///< avr-gcc and friends
  fs::path arduino;  ///< Arduino.mk, hardware/arduino/avr
  fs::path make;
  fs::path core() const { return arduino / "hardware" / "arduino" / "avr"; }
};

Toolchain find_toolchain(const SketchBuildOptions& options) {
  Toolchain t;
  t.bin = options.toolchain_dir.empty() ? fs::path("/usr/bin") : options.toolchain_dir;
  t.arduino = options.arduino_dir.empty() ? fs::path("/usr/share/arduino") : options.arduino_dir;
  auto missing = [](const std::string& what, const fs::path& where) {
    return SketchBuildError(Kind::kToolchain, what + " not found (looked for " + where.string() +
                                                  ")" + std::string(kInstallHint));
  };
  for (const char* tool : {"avr-gcc", "avr-g++", "avr-gcc-ar", "avr-objcopy"}) {
    if (::access((t.bin / tool).c_str(), X_OK) != 0) throw missing(tool, t.bin / tool);
  }
  const fs::path io_h = t.bin.parent_path() / "lib" / "avr" / "include" / "avr" / "io.h";
  std::error_code ec;
  if (!fs::exists(io_h, ec)) throw missing("avr-libc", io_h);
  if (!fs::exists(t.core() / "cores" / "arduino" / "Arduino.h", ec))
    throw missing("the Arduino AVR core (arduino-core-avr)", t.core() / "cores/arduino/Arduino.h");
  if (!fs::exists(t.arduino / "Arduino.mk", ec))
    throw missing("arduino-mk", t.arduino / "Arduino.mk");
  const auto make = find_in_path("make");
  if (!make) throw missing("make", "make in $PATH");
  t.make = *make;
  // The folders go into a Makefile, which hands them to the shell.
  for (const auto& dir : {t.bin, t.arduino}) {
    if (!is_plain_path(fs::absolute(dir))) {
      throw SketchBuildError(Kind::kToolchain,
                             dir.string() +
                                 ": the toolchain folders may hold only letters, "
                                 "digits and '_' '-' '.' '+' '/' (arduino-mk hands "
                                 "them to the shell)");
    }
  }
  return t;
}

/// `version=` of the core's platform.txt ("1.8.7").
std::string core_version(const Toolchain& t) {
  std::istringstream in(read_file(t.core() / "platform.txt"));
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("version=")) return line.substr(8);
  }
  return "unknown";
}

/// "1.8.7" as the ARDUINO macro writes it: 10807.
std::string arduino_macro(const std::string& version) {
  int parts[3] = {0, 0, 0};
  std::istringstream in(version);
  char dot = 0;
  in >> parts[0] >> dot >> parts[1] >> dot >> parts[2];
  return std::to_string(parts[0] * 10000 + parts[1] * 100 + parts[2]);
}

std::string first_line(const std::string& text) {
  return text.substr(0, text.find('\n'));
}

/// The Makefile of a build folder: arduino-mk for an Uno, every location
/// given (nothing looked up from the user's IDE preferences or
/// sketchbook), and the core's own warnings left out of what hil shows.
std::string makefile(const Toolchain& t, const std::string& version) {
  const std::string bin = fs::absolute(t.bin).string();
  const std::string arduino = fs::absolute(t.arduino).string();
  std::string mk;
  mk += "ARDUINO_DIR = " + arduino + "\n";
  mk += "ARDMK_DIR = " + arduino + "\n";
  mk += "AVR_TOOLS_DIR = " + fs::absolute(t.bin).parent_path().string() + "\n";
  mk += "AVR_TOOLS_PATH = " + bin + "\n";
  mk += "ARCHITECTURE = avr\n";
  mk += "ARDUINO_VERSION = " + arduino_macro(version) + "\n";
  mk += "BOARD_TAG = uno\n";
  mk += "ARDUINO_SKETCHBOOK = no-sketchbook\n";
  mk += "ARDUINO_QUIET = 1\n";
  mk += "TARGET = sketch\n";
  mk += "OBJDIR = obj\n";
  // avr-gcc 5.4's <float.h> has no DECIMAL_DIG for C++11, which the core's
  // WString.cpp needs; the compiler's own macro gives the same value.
  mk += "CPPFLAGS += -DDECIMAL_DIG=__DECIMAL_DIG__\n";
  mk += "obj/core/%: CPPFLAGS += -w\n";
  mk += "obj/libs/%: CPPFLAGS += -w\n";
  mk += "obj/platformlibs/%: CPPFLAGS += -w\n";
  mk += "include " + arduino + "/Arduino.mk\n";
  return mk;
}

fs::path default_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/')
    return fs::path(xdg) / "hil" / "firmware";
  const char* home = std::getenv("HOME");
  return fs::path(home != nullptr && *home != '\0' ? home : "/tmp") / ".cache" / "hil" / "firmware";
}

/// What the compilers printed, without make's own lines ("make: *** ...").
std::string without_make_lines(const std::string& output) {
  std::string out;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with("make:") && !line.starts_with("make[")) out += line + '\n';
  }
  return out;
}

/// The lines of a failed build that say what failed, at most `max_lines`:
/// the compiler's error lines, else the end of what make printed.
std::string error_lines(const std::string& output, std::size_t max_lines) {
  std::vector<std::string> picked;
  std::istringstream in(without_make_lines(output));
  for (std::string line; std::getline(in, line);) {
    std::string lower = line;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (lower.find("error") != std::string::npos ||
        lower.find("undefined reference") != std::string::npos ||
        lower.find("multiple definition") != std::string::npos)
      picked.push_back(line);
  }
  if (picked.empty()) {
    std::istringstream all(output);
    for (std::string line; std::getline(all, line);)
      picked.push_back(line);
    if (picked.size() > max_lines)
      picked.erase(picked.begin(), picked.end() - static_cast<std::ptrdiff_t>(max_lines));
  }
  std::string out;
  for (std::size_t i = 0; i < picked.size() && i < max_lines; ++i)
    out += "\n  " + picked[i];
  if (picked.size() > max_lines)
    out += "\n  (" + std::to_string(picked.size() - max_lines) + " more)";
  return out;
}

/// The sketch's sources as the build folder holds them: the .ino files as
/// one generated .cpp, the others with a #line naming their own path.
void write_build_sources(const Sketch& sketch, const fs::path& src) {
  std::vector<SketchFile> inos;
  for (const auto& s : sketch.sources) {
    if (s.path.extension() == ".ino") {
      inos.push_back({s.path, s.bytes});
    } else {
      std::string quoted;
      for (const char c : s.path.string()) {
        if (c == '\\' || c == '"') quoted += '\\';
        quoted += c;
      }
      write_file(src / s.name, "#line 1 \"" + quoted + "\"\n" + s.bytes);
    }
  }
  write_file(src / (sketch.ino.stem().string() + ".ino.cpp"), generate_sketch_cpp(inos));
}

void check_fits(const fs::path& elf, const fs::path& ino) {
  const AvrElfInfo info = read_avr_elf(elf);
  if (info.flash_bytes > kUnoFlashBytes || info.ram_bytes > kUnoRamBytes) {
    throw SketchBuildError(Kind::kCompile,
                           ino.string() +
                               ": does not fit an Uno: " + std::to_string(info.flash_bytes) +
                               " bytes of flash (of " + std::to_string(kUnoFlashBytes) + "), " +
                               std::to_string(info.ram_bytes) + " bytes of RAM (of " +
                               std::to_string(kUnoRamBytes) + ")");
  }
}

}  // namespace

std::string sha256(std::string_view bytes) {
  Sha256 h;
  h.update(bytes);
  return h.hex();
}

SketchBuild build(const fs::path& ino, const SketchBuildOptions& options) {
  const Sketch sketch = read_sketch(ino);
  const Toolchain tools = find_toolchain(options);
  const std::vector<std::string> env = build_environment();

  // The key: every input that can change the ELF.
  const ProcessResult gcc = run_process({(tools.bin / "avr-gcc").string(), "--version"}, env);
  const std::string version = core_version(tools);
  const std::string mk = makefile(tools, version);
  std::string inputs;  // what the key covers, but the sources' bytes
  inputs += std::string(kBuilderVersion) + "\n";
  inputs += "avr-gcc: " + first_line(gcc.output) + "\n";
  inputs += "arduino core: " + version + "\n";
  inputs += "arduino-mk: " + sha256_hex(read_file(tools.arduino / "Arduino.mk")) + "\n";
  inputs += "main: " + sketch.ino.filename().string() + "\n";
  Sha256 key_hash;
  key_hash.update(inputs);
  key_hash.update(mk);
  for (const auto& s : sketch.sources) {
    const std::string line =
        "file: " + s.name + " " + std::to_string(s.bytes.size()) + " " + sha256_hex(s.bytes) + "\n";
    inputs += line;
    key_hash.update(line);
  }
  SketchBuild result;
  result.key = key_hash.hex();

  const fs::path cache = options.cache_dir.empty() ? default_cache_dir() : options.cache_dir;
  const fs::path entry = cache / result.key;
  const fs::path cached_elf = entry / "sketch.elf";
  std::error_code ec;
  if (fs::is_regular_file(cached_elf, ec)) {
    result.cached = true;
  } else {
    fs::create_directories(cache, ec);
    if (ec) {
      throw SketchBuildError(
          Kind::kIo, "cannot make the cache folder " + cache.string() + ": " + ec.message());
    }
    const TempDir build(cache);
    const fs::path src = build.path() / "src";
    fs::create_directory(src);
    write_file(src / "Makefile", mk);
    write_build_sources(sketch, src);
    const int jobs = options.jobs > 0
                         ? options.jobs
                         : static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
    const ProcessResult made = run_process({tools.make.string(), "-s", "-j" + std::to_string(jobs),
                                            "-C", src.string(), "obj/sketch.elf"},
                                           env);
    if (made.exit_code != 0) {
      throw SketchBuildError(
          Kind::kCompile,
          sketch.ino.string() + ": does not compile:" + error_lines(made.output, 30),
          without_make_lines(made.output));
    }
    check_fits(src / "obj" / "sketch.elf", sketch.ino);
    result.warnings = without_make_lines(made.output);
    // The entry appears whole, in one rename; a build of the same sketch
    // that finished first has already put the same ELF there.
    const fs::path out = build.path() / "entry";
    fs::create_directory(out);
    fs::copy_file(src / "obj" / "sketch.elf", out / "sketch.elf", ec);
    if (ec) throw SketchBuildError(Kind::kIo, "cannot copy the ELF: " + ec.message());
    write_file(out / "inputs.txt", inputs);
    // An entry without its ELF (entries appear whole, so someone removed it).
    if (fs::exists(entry, ec) && !fs::exists(cached_elf, ec)) fs::remove_all(entry, ec);
    if (std::rename(out.c_str(), entry.c_str()) != 0 && !fs::is_regular_file(cached_elf, ec)) {
      throw SketchBuildError(
          Kind::kIo, "cannot move the build into " + entry.string() + ": " + std::strerror(errno));
    }
  }
  result.elf = cached_elf;
  if (!options.output.empty()) {
    copy_atomically(cached_elf, options.output);
    result.elf = options.output;
  }
  return result;
}

AvrElfInfo read_elf(const fs::path& elf) {
  const std::string bytes = read_file(elf);
  auto fail = [&](const std::string& why) {
    return SketchBuildError(Kind::kIo, elf.string() + ": " + why);
  };
  auto u16 = [&](std::size_t at) -> std::uint32_t {
    if (at + 2 > bytes.size()) throw fail("truncated ELF file");
    return std::uint32_t{static_cast<std::uint8_t>(bytes[at])} |
           (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 1])} << 8);
  };
  auto u32 = [&](std::size_t at) -> std::uint32_t { return u16(at) | (u16(at + 2) << 16); };
  constexpr std::string_view kMagic = "\177ELF";
  if (bytes.size() < 52 || !std::string_view(bytes).starts_with(kMagic))
    throw fail("not an ELF file");
  if (bytes[4] != 1 || bytes[5] != 1) throw fail("not a 32-bit little-endian ELF file");
  AvrElfInfo info;
  info.machine = static_cast<std::uint16_t>(u16(18));
  info.architecture = u32(36) & 0x7FU;
  const std::size_t shoff = u32(32);
  const std::size_t shentsize = u16(46);
  const std::size_t shnum = u16(48);
  const std::size_t shstrndx = u16(50);
  if (shnum == 0 || shstrndx >= shnum || shentsize < 40) return info;
  const std::size_t names = u32(shoff + shstrndx * shentsize + 16);
  for (std::size_t i = 0; i < shnum; ++i) {
    const std::size_t header = shoff + i * shentsize;
    const std::size_t name_at = names + u32(header);
    if (name_at >= bytes.size()) throw fail("truncated ELF file");
    const std::string name = bytes.c_str() + name_at;
    const std::uint32_t size = u32(header + 20);
    if (name == ".text" || name == ".data") info.flash_bytes += size;
    if (name == ".data" || name == ".bss" || name == ".noinit") info.ram_bytes += size;
  }
  return info;
}

}  // namespace sketch_build_impl

std::string sha256_hex(std::string_view bytes) {
  return sketch_build_impl::sha256(bytes);
}

SketchBuild build_sketch(const std::filesystem::path& ino, const SketchBuildOptions& options) {
  return sketch_build_impl::build(ino, options);
}

AvrElfInfo read_avr_elf(const std::filesystem::path& elf) {
  return sketch_build_impl::read_elf(elf);
}

}  // namespace hil::mocks::avr
