// What the viewer is served (view/run_view.hpp): the page and three.js compiled in, a run's data
// as JSON, the map's octree nodes as bytes; clear errors for what cannot be shown.
#include "taiga/view/run_view.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/las_writer.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga::view {
namespace {

using ::testing::HasSubstr;

/// A run directory as `taiga run` leaves it, small: a map of a 20 m line of points, a walk along
/// it, three keyframes with one accepted loop between the first and the last, four scans.
std::filesystem::path writeRun(const test::TempDir& dir) {
  const auto run = dir.file("run");
  std::filesystem::create_directories(run);
  PointCloud map;
  for (int i = 0; i < 30000; ++i) {
    map.positions.emplace_back(1000.0 + 0.001 * i * 20.0 / 30.0, 2000.0 + (i % 7) * 0.1, i % 13);
    map.intensities.push_back(static_cast<float>(i % 50));
  }
  {
    io::LasWriter writer(run / "map.las");
    writer.append(map);
    writer.close();
  }
  Trajectory walk, keyframes;
  for (int i = 0; i < 4; ++i)
    walk.append(10.0 + 0.1 * i, lie::SE3(lie::SO3(), Eigen::Vector3d(1000.0 + i, 2000.0, 1.5)));
  for (int i = 0; i < 3; ++i)
    keyframes.append(10.0 + 0.1 * i,
                     lie::SE3(lie::SO3(), Eigen::Vector3d(1000.0 + i, 2000.0, 1.5)));
  io::writeTum(run / "trajectory.tum", walk);
  io::writeTum(run / "keyframes.tum", keyframes);
  std::ofstream(run / "loops.csv")
      << "t_s,keyframe,candidate,distance_m,search_radius_m,fitness_m2,correction_m,correction_"
         "deg,chi2,accepted,note\n"
      << "10.2,2,0,2.0,5.0,0.05,0.01,0.1,1.0,1,\"\"\n"
      << "10.2,2,1,1.0,5.0,0.50,0.01,0.1,1.0,0,\"fitness\"\n";
  std::ofstream(run / "timing.csv")
      << "t_s,read_ms,total_ms\n10.0,1,5.5\n10.1,1,6.5\n10.2,1,40\n10.3,1,7\n";
  std::ofstream(run / "scans.csv") << "t_s,status\n10.0,ok\n10.1,ok\n10.2,degraded\n10.3,ok\n";
  std::ofstream(run / "trees.csv") << "id,x_m,y_m,z_m,dbh_m\n1,1005.0,2000.5,0.1,0.25\n"
                                   << "2,1010.0,2001.0,0.2,0.31\n";
  std::ofstream(run / "summary.json")
      << R"({"health": {"verdict": "ok", "scans_ok": 3}, "time_per_scan_ms": {"p50": 6.0},
            "realtime_factor": 9.5, "recording": "not passed on"})";
  return run;
}

TEST(RunView, ServesThePageAndThreeJsCompiledIn) {
  test::TempDir dir;
  const RunView view = RunView::load(writeRun(dir));
  const stream::HttpResponse page = view.get("/");
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.content_type, "text/html");
  EXPECT_THAT(page.body, HasSubstr("/viewer.js"));
  EXPECT_EQ(view.get("/index.html").body, page.body);
  const stream::HttpResponse three = view.get("/three/three.module.js?v=1");
  EXPECT_EQ(three.status, 200);
  EXPECT_EQ(three.content_type, "text/javascript");
  EXPECT_GT(three.body.size(), 100000u);
  EXPECT_THAT(view.get("/three/OrbitControls.js").body, HasSubstr("class OrbitControls"));
  EXPECT_EQ(view.get("/nothing").status, 404);
  EXPECT_EQ(view.get("/three/../index.html").status, 404);
}

TEST(RunView, InfoHasTheWalkKeyframesAcceptedLoopsAndScansRelativeToTheOrigin) {
  test::TempDir dir;
  const RunView view = RunView::load(writeRun(dir));
  const nlohmann::json info = nlohmann::json::parse(view.get("/api/info").body);
  EXPECT_EQ(info["mode"], "run");
  EXPECT_EQ(info["points"], 30000);
  const Eigen::Vector3d origin(info["origin"][0], info["origin"][1], info["origin"][2]);
  EXPECT_EQ(origin, Eigen::Vector3d(1000.0, 2000.0, 0.0));
  ASSERT_EQ(info["trajectory"].size(), 4u);
  EXPECT_NEAR(info["trajectory"][3][0].get<double>(), 10.3, 1e-9);  // t, x, y, z
  EXPECT_NEAR(info["trajectory"][3][1].get<double>(), 3.0, 1e-9);
  EXPECT_NEAR(info["trajectory"][3][3].get<double>(), 1.5, 1e-9);
  EXPECT_EQ(info["keyframes"].size(), 3u);
  ASSERT_EQ(info["loops"].size(), 1u);  // the rejected attempt is not drawn
  EXPECT_NEAR(info["loops"][0][0][0].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(info["loops"][0][1][0].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(info["scans"]["ms"], nlohmann::json::parse("[5.5, 6.5, 40, 7]"));
  EXPECT_EQ(info["scans"]["status"][2], "degraded");
  EXPECT_EQ(info["summary"]["health"]["verdict"], "ok");
  EXPECT_EQ(info["summary"]["realtime_factor"], 9.5);
  EXPECT_FALSE(info["summary"].contains("recording"));
  ASSERT_EQ(info["trees"].size(), 2u);  // x, y, ground z, DBH, height (none in this file)
  EXPECT_EQ(info["trees"][0], nlohmann::json::parse("[5.0, 0.5, 0.1, 0.25, null]"));
  EXPECT_NEAR(info["trees"][1][3].get<double>(), 0.31, 1e-12);
}

TEST(RunView, NodesAreServedAsFloatsAndAddUpToTheMap) {
  test::TempDir dir;
  const RunView view = RunView::load(writeRun(dir));
  const nlohmann::json nodes = nlohmann::json::parse(view.get("/api/nodes").body);
  ASSERT_EQ(nodes.size(), view.tree().nodes().size());
  ASSERT_GT(nodes.size(), 1u);
  std::size_t total = 0;
  for (std::size_t id = 0; id < nodes.size(); ++id) {
    const stream::HttpResponse r = view.get("/api/node/" + std::to_string(id));
    ASSERT_EQ(r.status, 200);
    EXPECT_EQ(r.content_type, "application/octet-stream");
    EXPECT_EQ(r.body.size(), nodes[id]["points"].get<std::size_t>() * 16);
    total += nodes[id]["points"].get<std::size_t>();
  }
  EXPECT_EQ(total, 30000u);
  for (const char* bad : {"/api/node/", "/api/node/-1", "/api/node/1x", "/api/node/99999999"})
    EXPECT_EQ(view.get(bad).status, 404) << bad;
}

TEST(RunView, ACloudFileAloneIsShownWithoutAWalk) {
  test::TempDir dir;
  const auto run = writeRun(dir);
  const RunView view = RunView::load(run / "map.las");
  const nlohmann::json info = nlohmann::json::parse(view.get("/api/info").body);
  EXPECT_EQ(info["name"], "map.las");
  EXPECT_EQ(info["points"], 30000);
  EXPECT_TRUE(info["trajectory"].empty());
  EXPECT_TRUE(info["scans"]["ms"].empty());  // side files come from run directories only
  EXPECT_TRUE(info["trees"].empty());
}

TEST(RunView, WhatCannotBeShownIsNamed) {
  test::TempDir dir;
  const auto empty_dir = dir.file("empty");
  std::filesystem::create_directories(empty_dir);
  const auto message = [](const std::filesystem::path& path) {
    try {
      RunView::load(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message(empty_dir), HasSubstr("without map.las"));
  EXPECT_THAT(message(dir.file("missing.las")), HasSubstr("missing.las: no such file"));
  EXPECT_THAT(message(dir.write("map.txt", "1 2 3\n")), HasSubstr("expected a .las, .ply or .pcd"));
  EXPECT_THAT(message(dir.write("broken.las", "LASF")), HasSubstr("broken.las"));
  const auto run = writeRun(dir);
  std::ofstream(run / "timing.csv") << "not a timing file\n";
  EXPECT_THAT(message(run), HasSubstr("timing.csv"));
}

TEST(RunView, TheLiveViewServesThePageAndSaysItIsLive) {
  EXPECT_EQ(liveViewResponse("/").status, 200);
  EXPECT_EQ(nlohmann::json::parse(liveViewResponse("/api/info").body)["mode"], "live");
  EXPECT_EQ(liveViewResponse("/api/nodes").status, 404);
}

}  // namespace
}  // namespace taiga::view
