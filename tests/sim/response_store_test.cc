// The response store against the prediction it keeps: a stored response is the one
// PredictBundleResponse makes, bit for bit, and any changed input is a miss.
#include "sim/response_store.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>

namespace recruit::sim {
namespace file_response_store_test {

// The two-state chain (broadcast_transition_model.h): A = [[1 - p_on, p_off], [p_on, 1 - p_off]].
estimation::BroadcastTransitionModel TwoState() {
  estimation::BroadcastTransitionModel c;
  c.state_names = {"off", "on"};
  c.is_on = {false, true};
  c.interior = Eigen::MatrixXd::Identity(2, 2);
  c.on_target = {1, -1};
  c.off_target = {-1, 0};
  c.dt = 1.0;
  return c;
}

void ExpectSame(const control::ActuatorResponse& a, const control::ActuatorResponse& b) {
  EXPECT_EQ(a.dT, b.dT);
  EXPECT_EQ(a.s, b.s);  // exact: vector equality compares every double with ==
  EXPECT_EQ(a.release, b.release);
}

TEST(ResponseStore, GivesThePredictionBitForBitAndMissesOnAnyChangedInput) {
  const std::string folder = (std::filesystem::temp_directory_path() /
                              ("recruit_response_store_" + std::to_string(getpid())))
                                 .string();
  std::filesystem::remove_all(folder);
  ::setenv("RECRUIT_DESIGN_CACHE", folder.c_str(), 1);
  const estimation::BroadcastTransitionModel chain = TwoState();
  const std::vector<double> force = {0.0, 1.0};
  auto direct = control::PredictBundleResponse(chain, force, 0.2);
  ASSERT_TRUE(direct.ok()) << direct.error();
  ASSERT_GT(direct->s.size(), 2u);
  auto cold = StoredBundleResponse(chain, force, 0.2);  // computed and stored
  ASSERT_TRUE(cold.ok());
  ExpectSame(*cold, *direct);
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(folder))
    entries += e.path().extension() == ".response";
  EXPECT_EQ(entries, 1);
  auto warm = StoredBundleResponse(chain, force, 0.2);  // read back
  ASSERT_TRUE(warm.ok());
  ExpectSame(*warm, *direct);
  // Another lambda, force row or chain: a new prediction, the same as the direct one.
  auto other = StoredBundleResponse(chain, force, 0.3);
  ASSERT_TRUE(other.ok());
  ExpectSame(*other, *control::PredictBundleResponse(chain, force, 0.3));
  estimation::BroadcastTransitionModel slow = chain;
  slow.dt = 2.0;
  auto other_chain = StoredBundleResponse(slow, force, 0.2);
  ASSERT_TRUE(other_chain.ok());
  ExpectSame(*other_chain, *control::PredictBundleResponse(slow, force, 0.2));
  // A damaged entry is a miss: the prediction again.
  for (const auto& e : std::filesystem::directory_iterator(folder)) {
    std::filesystem::resize_file(e.path(), std::filesystem::file_size(e.path()) - 3);
  }
  auto damaged = StoredBundleResponse(chain, force, 0.2);
  ASSERT_TRUE(damaged.ok());
  ExpectSame(*damaged, *direct);
  ::unsetenv("RECRUIT_DESIGN_CACHE");
  std::filesystem::remove_all(folder);
}

}  // namespace file_response_store_test
}  // namespace recruit::sim
