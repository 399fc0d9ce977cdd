// The Cortex-M4F side of tests/export: an exported package cross-compiled with Debian's
// gcc-arm-none-eabi, its flash and RAM read from the tools' reports, and a recorded log replayed
// on QEMU's MPS2 board (mps2-an386) and by a host build of the same source (tests/export/m4/).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/export/package_loader.h"

namespace recruit::exporter::testing {

inline constexpr const char* kM4Flags =
    "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -std=c99 -Os -ffp-contract=off "
    "-fno-math-errno -Wall -Wextra -Wdouble-promotion -Werror -ffunction-sections "
    "-fdata-sections";

inline bool HasM4Tools() { return HasTool("arm-none-eabi-gcc") && HasTool("qemu-system-arm"); }

inline std::string ReadText(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A value as the float bit pattern replay.c reads ("%08lx").
inline std::string FloatHex(double v) {
  const float f = static_cast<float>(v);
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08lx", static_cast<unsigned long>(u));
  return buf;
}

// A package written into `dir`, built and run there.
class M4Package {
 public:
  explicit M4Package(std::filesystem::path dir) : dir_(std::move(dir)) {}
  const std::filesystem::path& dir() const { return dir_; }
  // tests/export/m4/ in the source tree.
  static std::string Sources() { return std::string(RECRUIT_SOURCE_DIR) + "/tests/export/m4/"; }
  static std::string Cc() { return std::string("arm-none-eabi-gcc ") + kM4Flags; }

  // Runs `cmd` in the folder; a failure is a test failure showing the command's output.
  bool Sh(const std::string& cmd) const {
    const int rc = Shell("cd " + dir_.string() + "/ && ( " + cmd + " ) > cmd.log 2>&1");
    EXPECT_EQ(rc, 0) << cmd << "\n" << ReadText(dir_ / "cmd.log");
    return rc == 0;
  }

  // The objects of `sources` compiled with stack usage, and size.elf linked from
  // recruit_controller.o and size_main.c (the smallest caller, no stdio); size.txt, nm.txt and
  // undefined.txt written by the binutils.
  bool BuildForSize(const std::string& sources, const std::string& objects) const {
    const std::string m4 = Sources();
    return Sh(Cc() + " -fstack-usage -c " + sources) &&
           Sh(Cc() + " -I. -nostdlib -T " + m4 + "m4.ld -Wl,--gc-sections " + m4 + "startup.c " +
              m4 + "size_main.c recruit_controller.o -lm -lc -lgcc -o size.elf") &&
           Sh("arm-none-eabi-size " + objects + " size.elf > size.txt && arm-none-eabi-nm -S " +
              "size.elf > nm.txt && arm-none-eabi-nm -u recruit_controller.o > undefined.txt");
  }

  // What BuildForSize's reports say: the controller object's text, the program's text, data and
  // bss, the size of the statics named in `context` and every stack frame of the controller
  // added up (an upper bound of its deepest call chain).
  struct Footprint {
    unsigned long object_text = 0, text = 0, data = 0, bss = 0, context = 0, stack = 0;
  };
  Footprint ReadFootprint(const std::set<std::string>& context) const {
    Footprint f;
    std::istringstream size(ReadText(dir_ / "size.txt"));
    for (std::string line; std::getline(size, line);) {
      unsigned long t, da, b;
      char name[256];
      if (std::sscanf(line.c_str(), "%lu %lu %lu %*u %*x %255s", &t, &da, &b, name) != 4) continue;
      if (std::string(name) == "size.elf") f.text = t, f.data = da, f.bss = b;
      if (std::string(name) == "recruit_controller.o") f.object_text = t;
    }
    std::istringstream nm(ReadText(dir_ / "nm.txt"));
    for (std::string line; std::getline(nm, line);) {
      unsigned long addr, bytes;
      char type, name[256];
      if (std::sscanf(line.c_str(), "%lx %lx %c %255s", &addr, &bytes, &type, name) == 4 &&
          (type == 'b' || type == 'B') && context.count(name)) {
        f.context += bytes;
      }
    }
    std::istringstream su(ReadText(dir_ / "recruit_controller.su"));
    for (std::string line; std::getline(su, line);) {
      const size_t tab = line.find('\t');
      if (tab != std::string::npos) f.stack += std::strtoul(line.c_str() + tab + 1, nullptr, 10);
    }
    return f;
  }

  // No heap, nothing but the math library: the controller object needs no symbol beyond libm's.
  void ExpectNoHeapOrStdio() const {
    const std::string undefined = ReadText(dir_ / "undefined.txt");
    for (const char* bad : {"malloc", "free", "printf", "sbrk"}) {
      EXPECT_EQ(undefined.find(bad), std::string::npos) << undefined;
    }
  }

  // replay.c over log.txt (written by the caller: a header line, then one line of FloatHex
  // inputs per instant), built for the host (host.txt) and for the M4 under QEMU (m4.txt).
  bool ReplayOnHostAndM4(int qemu_timeout_s) const {
    const std::string m4 = Sources();
    return Sh(std::string(RECRUIT_HOST_CC) + " " + HostCFlags() + " -I. recruit_controller.c " +
              m4 + "replay.c -lm -o replay_host && ./replay_host log.txt > host.txt") &&
           Sh(Cc() + " -I. -DUSE_NEWLIB -DM4_SYSTICK -nostartfiles --specs=rdimon.specs -T " + m4 +
              "m4.ld -Wl,--gc-sections " + m4 + "startup.c " + m4 +
              "replay.c recruit_controller.c -lm -o replay.elf") &&
           Sh("timeout " + std::to_string(qemu_timeout_s) +
              " qemu-system-arm -M mps2-an386 -nographic -no-reboot -icount shift=0 "
              "-semihosting-config enable=on,target=native -kernel replay.elf -append log.txt > "
              "m4.txt");
  }

  // replay.c's output: per instant and bundle a row "k i" and the five outputs' bit patterns;
  // the SysTick ticks and steps.
  struct Replayed {
    std::vector<std::string> rows;
    unsigned long ticks = 0;
    int steps = 0;
  };
  Replayed ReadReplay(const std::string& file) const {
    Replayed r;
    std::istringstream in(ReadText(dir_ / file));
    for (std::string line; std::getline(in, line);) {
      if (std::sscanf(line.c_str(), "ticks %lu steps %d", &r.ticks, &r.steps) == 2) continue;
      if (!line.empty()) r.rows.push_back(line);
    }
    return r;
  }

 private:
  std::filesystem::path dir_;
};

}  // namespace recruit::exporter::testing
