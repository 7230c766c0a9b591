// Issue 7: the map on demand while running. `taiga export-map RUN/keyframes` from another shell,
// while `taiga run --realtime` is still going, writes the map of the keyframes so far; the run
// is not disturbed and ends with its full map.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/io/las_reader.hpp"

namespace taiga::mapping {
namespace {

using ::testing::HasSubstr;

TEST(LiveExportCli, ExportsTheMapOfARunThatIsStillGoing) {
  test::TempDir dir;
  const auto sim = dir.file("sim");
  // 32 beams: with 16 this walk's odometry diverges from its start (APE 17 m, also before the
  // health monitor, which now says so and exits 3).
  ASSERT_EQ(test::runTaiga("simulate --scenario mixed --duration 15 --beams 32 --columns 512 "
                           "--sub-rays 1 --seed 3 --out " +
                           sim.string())
                .exit_code,
            0);
  const std::string taiga = TAIGA_EXECUTABLE;
  const auto run = dir.file("run");
  const auto poses = run / "keyframes" / "poses.tum";
  // --realtime paces the 15 s recording at sensor rate, so the run is still going when the
  // keyframes file lists 5 keyframes; the export starts then, and the script reports whether
  // the run was still alive after it.
  const std::string script =
      taiga + " run " + (sim / "recording.bag").string() + " --config " +
      (sim / "rig.yaml").string() + " --realtime --out " + run.string() + " > " +
      dir.file("run.log").string() + " 2>&1 & pid=$!\n" + "for i in $(seq 600); do [ -f " +
      poses.string() + " ] && [ $(grep -vc '^#' " + poses.string() +
      ") -ge 5 ] && break; sleep 0.05; done\n" + taiga + " export-map " +
      (run / "keyframes").string() + " --out " + dir.file("live.las").string() +
      "; echo \"export exit $?\"\n" + "kill -0 $pid 2>/dev/null && echo 'run still going'\n" +
      "wait $pid; echo \"run exit $?\"\n";
  const auto script_path = dir.write("live.sh", script);
  std::string output;
  {
    std::FILE* pipe = popen(("sh " + script_path.string() + " 2>&1").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    pclose(pipe);
  }
  EXPECT_THAT(output, HasSubstr("export exit 0"));
  EXPECT_THAT(output, HasSubstr("run still going"));
  EXPECT_THAT(output, HasSubstr("run exit 0"));

  const std::uint64_t live_points = io::LasReader(dir.file("live.las")).pointCount();
  const std::uint64_t final_points = io::LasReader(run / "map.las").pointCount();
  EXPECT_GT(live_points, 0u) << output;
  EXPECT_LT(live_points, final_points) << "the live map holds only the keyframes so far";
}

}  // namespace
}  // namespace taiga::mapping
