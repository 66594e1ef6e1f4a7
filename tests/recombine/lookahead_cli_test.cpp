// `quadval recombine --algo lookahead` end to end (issue 8): exit codes, an all-quad output
// with --full-quad, the report's lookahead block, and the same output for the same seed
// whatever the thread count (OMP_NUM_THREADS).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include "cli_run.hpp"
#include "quadval/io.hpp"

namespace quadval {
namespace {

namespace fs = std::filesystem;

using testing_cli::slurp;

class LookaheadCli : public ::testing::Test {
 protected:
  void SetUp() override {
    input_ = fs::path(QUADVAL_SHARED_DIR) / "data/tri/rect-sin-a6.msh";
    if (!fs::exists(input_)) GTEST_SKIP() << input_ << " missing";
    dir_ = fs::temp_directory_path() / ("qv_lookahead_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // Runs the CLI with OMP_NUM_THREADS=threads; returns the exit code, output in output_.
  int run(const std::string& args, int threads = 1) {
    const fs::path log = dir_ / "log.txt";
    const std::string cmd = "OMP_NUM_THREADS=" + std::to_string(threads) + " " +
                            QUADVAL_CLI_PATH + " " + args + " > " + log.string() + " 2>&1";
    const int rc = std::system(cmd.c_str());
    output_ = slurp(log);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  fs::path input_, dir_;
  std::string output_;
};

TEST_F(LookaheadCli, FullQuadRunGivesAllQuadsAndTheLookaheadReport) {
  const fs::path out = dir_ / "q.msh", report = dir_ / "r.json";
  ASSERT_EQ(run("recombine " + input_.string() + " -o " + out.string() + " --report " +
                report.string() +
                " --algo lookahead --horizon 3 --seed 11 --runs 4 --full-quad --compare-blossom"),
            0)
      << output_;
  EXPECT_NE(output_.find("look-ahead: q"), std::string::npos) << output_;
  const Mesh q = read_mesh(out);
  std::size_t quads = 0, others = 0;
  for (const auto& b : q.blocks) (b.type->gmsh_id == 3 ? quads : others) += b.size();
  EXPECT_GT(quads, 0u);
  EXPECT_EQ(others, 0u);

  const auto j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j.at("algorithm"), "lookahead");
  const auto& s = j.at("statistics");
  EXPECT_EQ(s.at("quads").get<std::size_t>(), quads);
  EXPECT_EQ(s.at("triangles_left").get<std::size_t>(), 0u);
  const auto& la = j.at("lookahead");
  EXPECT_EQ(la.at("tree"), "selective");
  EXPECT_EQ(la.at("horizon"), 3);
  EXPECT_EQ(la.at("seed"), 11);
  const auto& runs = la.at("runs");
  ASSERT_EQ(runs.size(), 4u);
  // Best run: the largest quality, ties to the lowest index (the documented rule).
  std::size_t best = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs[i].at("seed").get<std::uint64_t>(), 11 + i);
    if (runs[i].at("quality").get<double>() > runs[best].at("quality").get<double>()) best = i;
  }
  EXPECT_EQ(la.at("best_run").get<std::size_t>(), best);
  EXPECT_EQ(la.at("quality").get<double>(), runs[best].at("quality").get<double>());
  // Counts: triangles in (after parity splits) = 2 quads merged + triangles left.
  const auto n = s.at("input_triangles").get<std::size_t>() + s.at("odd_splits").get<std::size_t>();
  const auto left = la.at("triangles_left_before_post_process").get<std::size_t>();
  EXPECT_EQ(left, runs[best].at("triangles_left").get<std::size_t>());
  EXPECT_EQ(n, 2 * runs[best].at("quads").get<std::size_t>() + left);
  EXPECT_NEAR(la.at("recombined_share").get<double>(), 1.0 - static_cast<double>(left) / n, 1e-12);
  EXPECT_EQ(la.at("triangles_left_after_post_process").get<std::size_t>(), 0u);
  // Each quad's eta is at most 1: q <= #quads.
  EXPECT_LE(la.at("quality").get<double>(), runs[best].at("quads").get<double>());
  const double blossom = la.at("blossom_quality").get<double>();
  ASSERT_GT(blossom, 0.0);
  EXPECT_NEAR(la.at("quality_percent_of_blossom").get<double>(),
              100.0 * la.at("quality").get<double>() / blossom, 1e-9);
}

TEST_F(LookaheadCli, SameSeedGivesTheSameOutputForAnyThreadCount) {
  std::string mesh[2], best[2];
  for (int k = 0; k < 2; ++k) {
    const fs::path out = dir_ / ("q" + std::to_string(k) + ".msh");
    const fs::path report = dir_ / ("r" + std::to_string(k) + ".json");
    ASSERT_EQ(run("recombine " + input_.string() + " -o " + out.string() + " --report " +
                      report.string() + " --algo lookahead --horizon 2 --seed 5 --runs 6 -q",
                  k == 0 ? 1 : 4),
              0)
        << output_;
    mesh[k] = slurp(out);
    auto la = nlohmann::json::parse(slurp(report)).at("lookahead");
    for (auto& r : la.at("runs")) r.erase("seconds");  // timings differ, nothing else may
    best[k] = la.dump();
  }
  EXPECT_FALSE(mesh[0].empty());
  EXPECT_EQ(mesh[0], mesh[1]);
  EXPECT_EQ(best[0], best[1]);
}

TEST_F(LookaheadCli, BadHorizonExitsTwoWithMessage) {
  EXPECT_EQ(run("recombine " + input_.string() + " -o " + (dir_ / "q.msh").string() +
                " --algo lookahead --horizon 0"),
            2)
      << output_;
  EXPECT_NE(output_.find("horizon"), std::string::npos) << output_;
  EXPECT_FALSE(fs::exists(dir_ / "q.msh"));
}

}  // namespace
}  // namespace quadval
