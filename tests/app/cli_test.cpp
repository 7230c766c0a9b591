// The `taiga` command as users and scripts see it: exit codes, help, version and error messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

#include "../support/temp_dir.hpp"

namespace {

using ::testing::HasSubstr;

struct Result {
  int exit_code;
  std::string output;  // standard output and standard error together
};

Result runTaiga(const std::string& arguments) {
  const std::string command = std::string(TAIGA_EXECUTABLE) + " " + arguments + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  Result result{-1, ""};
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

TEST(Cli, PrintsItsVersion) {
  const Result r = runTaiga("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("taiga 0."));
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* name :
       {"simulate", "info", "export", "register", "run", "eval", "compare", "georef", "config"}) {
    const Result r = runTaiga(std::string(name) + " --help");
    EXPECT_EQ(r.exit_code, 0) << name;
    EXPECT_THAT(r.output, HasSubstr(std::string("Usage: ") + TAIGA_EXECUTABLE + " " + name))
        << name;
  }
}

TEST(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(runTaiga("").exit_code, 2);
  EXPECT_EQ(runTaiga("fly").exit_code, 2);
  const Result missing = runTaiga("eval --est a.tum");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("--ref is required"));
  const Result bad_choice = runTaiga("register a.ply b.ply --method icp");
  EXPECT_EQ(bad_choice.exit_code, 2);
  EXPECT_THAT(bad_choice.output, HasSubstr("icp not in {ndt,d2d,gicp}"));
}

TEST(Cli, UnbuiltSubcommandsSaySoAndFail) {
  const Result r = runTaiga("simulate --out /tmp/unused");
  EXPECT_EQ(r.exit_code, 69);
  EXPECT_THAT(r.output, HasSubstr("taiga simulate: not implemented yet"));
}

TEST(Cli, ConfigPrintsDefaultsAndNamesBadKeys) {
  const Result defaults = runTaiga("config");
  EXPECT_EQ(defaults.exit_code, 0);
  EXPECT_THAT(defaults.output, HasSubstr("T_body_lidar:"));

  taiga::test::TempDir dir;
  const auto typo = dir.write(
      "typo.yaml", "rig:\n  T_body_lidar:\n    rpy_deg: [0, 0, 180]\n  lidar_offset_s: 0.1\n");
  const Result r = runTaiga("config " + typo.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("taiga: error: " + typo.string() +
                                  ":4:3: rig.lidar_offset_s: unknown key"));

  const auto good = dir.write("good.yaml", "rig:\n  T_body_lidar:\n    rpy_deg: [0, 0, 180]\n");
  const Result ok = runTaiga("config " + good.string());
  EXPECT_EQ(ok.exit_code, 0);
  EXPECT_THAT(ok.output, HasSubstr("quaternion_xyzw: [0, 0, 1, 6.123233995736766e-17]"));
}

}  // namespace
