// A whole sweep through the library (sweep/sweep.h), as a program other than `recruit` would run
// it: the errors carry the class `recruit sweep` exits with, and a run writes what the CLI's does.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "common/exit_codes.h"
#include "sweep/sweep.h"

namespace recruit::sweep {
namespace file_sweep_definition_test {

namespace fs = std::filesystem;

const std::string kTask = std::string(RECRUIT_SOURCE_DIR) + "/models/tasks/isometric_steps.json";

TEST(SweepDefinition, ErrorsCarryTheirExitClass) {
  SweepDefinition d;
  auto none = Prepare(d);  // no task anywhere: a usage error
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(exit_code::Of(none.failure()), exit_code::kUsage);

  d.task = "/no/such/task.json";  // a path that names no file: bad input (the CLI's --task check
  d.given.insert("task");         // says usage first)
  auto missing = Prepare(d);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(exit_code::Of(missing.failure()), exit_code::kBadInput);

  d.task = kTask;
  d.dTs = {1.0};
  d.estimators = {"output"};
  d.seeds = 1;
  d.duration = 1;
  auto p = Prepare(d);
  ASSERT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p->grid.size(), 1u);
  EXPECT_FALSE(p->spec.identify_missing_models);  // a library user leaves it off
  d.out = "/proc/nonexistent/sweep";              // an output folder that cannot be made: I/O
  auto run = sweep::Run(*p, d, "", 1, {}, {});
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(exit_code::Of(run.failure()), exit_code::kIo);
  auto shard = sweep::Run(*p, d, "3/2", 1, {}, {});  // a bad shard: usage
  ASSERT_FALSE(shard.ok());
  EXPECT_EQ(exit_code::Of(shard.failure()), exit_code::kUsage);
}

TEST(SweepDefinition, AShardRunsAndWritesItsManifest) {
  const fs::path out =
      fs::temp_directory_path() / ("recruit_sweep_def_" + std::to_string(getpid()));
  fs::remove_all(out);
  SweepDefinition d;
  d.task = kTask;
  d.given.insert("task");
  d.dTs = {0.5, 1.0};
  d.estimators = {"output"};
  d.seeds = 1;
  d.duration = 2;
  d.out = out.string();
  auto p = Prepare(d);
  ASSERT_TRUE(p.ok()) << p.error();
  int started = -1;
  RunHooks hooks;
  hooks.starting = [&](int runs) { started = runs; };
  auto r = sweep::Run(*p, d, "1/2", 1, hooks, {});  // a shard draws nothing
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(started, 1);
  EXPECT_EQ(r->executed, 1);
  EXPECT_TRUE(fs::exists(out / "shard.json"));
  EXPECT_TRUE(fs::exists(out / "sweep.json"));
  // The same folder, another sweep (its id: task, duration, filter model, sweep file, shard):
  // refused as a usage error, nothing run.
  d.duration = 3;
  auto other = Prepare(d);
  ASSERT_TRUE(other.ok());
  auto again = sweep::Run(*other, d, "1/2", 1, {}, {});
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(exit_code::Of(again.failure()), exit_code::kUsage);
  fs::remove_all(out);
}

}  // namespace file_sweep_definition_test
}  // namespace recruit::sweep
