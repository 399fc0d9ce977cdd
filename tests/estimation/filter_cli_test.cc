// `recruit filter` run as a separate process: the documented worked example, every estimator,
// and bad input (clear message, non-zero exit, no output file).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"

namespace recruit {
namespace file_filter_cli_test {

namespace fs = std::filesystem;

struct RunResult {
  int exit_code;
  std::string err;
};

// Runs `recruit ARGS` with stderr captured to a file.
RunResult RunRecruit(const std::string& args) {
  // One file per process: ctest -j runs the CLI tests in parallel.
  const std::string err_path =
      ::testing::TempDir() + "/estimation_cli_stderr_" + std::to_string(::getpid()) + ".txt";
  const std::string cmd = std::string(RECRUIT_BINARY) + " " + args + " > /dev/null 2> " + err_path;
  const int status = std::system(cmd.c_str());
  RunResult r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, ""};
  auto text = ReadFile(err_path);
  if (text.ok()) r.err = *text;
  std::remove(err_path.c_str());
  return r;
}

std::string Src(const std::string& rel) { return std::string(RECRUIT_SOURCE_DIR) + "/" + rel; }

class EstimationCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("estimation_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string p = (dir_ / name).string();
    std::ofstream(p) << text;
    return p;
  }
  std::string Out() const { return (dir_ / "out.csv").string(); }
  // Nothing named out.csv* (neither the output nor a leftover temporary file).
  bool NoOutput() const {
    for (const auto& e : fs::directory_iterator(dir_)) {
      if (e.path().filename().string().rfind("out.csv", 0) == 0) return false;
    }
    return true;
  }
  fs::path dir_;
};

std::vector<std::vector<double>> ReadCsvNumbers(const std::string& path, std::string* header) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, *header);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

// The command of docs/formats/filter.md, on the committed worked example.
TEST_F(EstimationCli, DocumentedExampleRunsAndTracksTheTruth) {
  const std::string model = Src("models/filter/three_state_model.json");
  const std::string log = Src("models/filter/three_state_log.csv");
  const RunResult r = RunRecruit("filter --model " + model + " --log " + log +
                                 " --estimator extended --out " + Out());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string header;
  const auto rows = ReadCsvNumbers(Out(), &header);
  EXPECT_EQ(header, "step,t,updated,x_off,x_warming,x_on,var_off,var_warming,var_on");
  std::string truth_header;
  const auto truth = ReadCsvNumbers(Src("models/filter/three_state_truth.csv"), &truth_header);
  ASSERT_EQ(rows.size(), 80u);
  ASSERT_EQ(truth.size(), 80u);
  double se = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_NEAR(rows[k][3] + rows[k][4] + rows[k][5], 60.0, 1e-6);
    EXPECT_EQ(rows[k][2], k % 5 == 4 ? 0.0 : 1.0);  // every fifth measurement is missing
    for (int i = 0; i < 3; ++i) se += std::pow(rows[k][3 + i] - truth[k][2 + i], 2);
  }
  const double rmse = std::sqrt(se / rows.size());
  EXPECT_LT(rmse, 3.0) << "count RMSE against the simulated truth";
  // Same numbers as the library run in process.
  auto m = estimation::FilterModel::FromJson(model);
  ASSERT_TRUE(m.ok());
  auto f = estimation::MakeCountFilter(*m, {});
  ASSERT_TRUE(f.ok());
  auto csv = estimation::RunFilterOverText(*m, *ReadFile(log), log, **f);
  ASSERT_TRUE(csv.ok()) << csv.error();
  EXPECT_EQ(*ReadFile(Out()), *csv);
}

TEST_F(EstimationCli, EveryEstimatorRunsAndParticleSeedIsReproducible) {
  const std::string args = "filter --model " + Src("models/filter/three_state_model.json") +
                           " --log " + Src("models/filter/three_state_log.csv");
  for (const char* e : {"conservative", "plain", "exact"}) {
    const RunResult r = RunRecruit(args + " --estimator " + e + " --out " + Out());
    EXPECT_EQ(r.exit_code, 0) << e << ": " << r.err;
    EXPECT_TRUE(fs::exists(Out())) << e;
    fs::remove(Out());
  }
  const std::string a = (dir_ / "a.csv").string(), b = (dir_ / "b.csv").string(),
                    c = (dir_ / "c.csv").string();
  const std::string pf = args + " --estimator particle --particles 300 ";
  ASSERT_EQ(RunRecruit(pf + "--seed 5 --out " + a).exit_code, 0);
  ASSERT_EQ(RunRecruit(pf + "--seed 5 --out " + b).exit_code, 0);
  ASSERT_EQ(RunRecruit(pf + "--seed 6 --out " + c).exit_code, 0);
  EXPECT_EQ(*ReadFile(a), *ReadFile(b));
  EXPECT_NE(*ReadFile(a), *ReadFile(c));
}

TEST_F(EstimationCli, HelpListsEveryOption) {
  const std::string help_path = (dir_ / "help.txt").string();
  const int status =
      std::system((std::string(RECRUIT_BINARY) + " filter --help > " + help_path).c_str());
  ASSERT_EQ(WEXITSTATUS(status), 0);
  const std::string help = *ReadFile(help_path);
  for (const char* opt :
       {"--model", "--log", "--out", "--estimator", "--particles", "--seed", "--max-states"}) {
    EXPECT_NE(help.find(opt), std::string::npos) << opt;
  }
}

const char* kTwoStateModel = R"({
  "states": ["off", "on"], "N": 60, "H": [[0, 0.45]], "R": [[0.09]],
  "transition": {"type": "broadcast", "dt": 0.5, "is_on": [false, true],
                 "on_target": 1, "off_target": 0}})";

const char* kExplicitModel = R"({
  "states": ["off", "on"], "N": 60, "H": [[0, 0.45]], "R": [[0.09]],
  "transition": {"type": "explicit"}})";

const char* kGoodLog = "t,p_on,p_off,y\n0,0.2,0,0.1\n0.5,0.2,0,\n1,,,4.0\n";

struct BadCase {
  std::string name;
  std::string model;  // JSON text, or "" for a missing file
  std::string log;
  std::string extra;
  std::string expected;  // in stderr
  int code = 3;          // the exit code (docs/reliability.md): 3 bad input, 2 usage
};

TEST_F(EstimationCli, BadInputGivesClearMessageNonZeroExitAndNoOutput) {
  const std::vector<BadCase> cases = {
      {"non-stochastic A", kExplicitModel,
       "A_0_0,A_0_1,A_1_0,A_1_1,y\n0.9,0.1,0.1,0.8,1.0\n0.9,0.1,0.1,0.9,2.0\n", "",
       ":2: A: column 1 sums to 0.9, not 1 (tolerance 1e-09)"},
      {"negative counts",
       R"({"states": ["off", "on"], "N": 60, "H": [[0, 0.45]], "R": [[0.09]],
           "transition": {"type": "explicit"}, "initial": {"x0": [70, -10]}})",
       "A_0_0,A_0_1,A_1_0,A_1_1,y\n1,0,0,1,1.0\n", "",
       "initial.x0: entries must be finite and >= 0"},
      {"NaN measurement", kTwoStateModel, "t,p_on,p_off,y\n0,0.2,0,nan\n", "",
       ":2: column 'y': 'nan' is not a finite number"},
      {"probability above 1", kTwoStateModel, "t,p_on,p_off,y\n0,1.5,0,1\n", "",
       "p_on = 1.500000 must be a probability in [0, 1]"},
      {"wrong H dimensions",
       R"({"states": ["off", "on"], "N": 60, "H": [[0, 0.45, 1]], "R": [[0.09]],
           "transition": {"type": "explicit"}})",
       kGoodLog, "",
       ".H[0]: must be an array of 2 numbers (row 0 of a r x 2 matrix), got [0,0.45,1]"},
      {"malformed JSON", "{\"states\": [\"off\", \"on\"], \"N\": 60,", kGoodLog, "",
       "not valid JSON"},
      {"malformed CSV row", kTwoStateModel, "t,p_on,p_off,y\n0,0.2,0\n", "",
       ":2: has 3 cells, the header 4"},
      {"unknown CSV column", kTwoStateModel, "t,p_on,p_off,force\n0,0.2,0,1\n", "",
       "unknown column 'force'; this model's log has columns: t (optional), p_on, p_off, y"},
      {"inputs missing mid-log", kTwoStateModel, "p_on,p_off,y\n0.2,0,1\n,,2\n0.1,0.1,3\n", "",
       ":3: inputs are empty; only the last row may omit them"},
      {"empty log", kTwoStateModel, "", "", "empty log"},
      {"missing model file", "", kGoodLog, "", "model.json", 2},
      {"exact filter too large",
       R"({"states": ["a", "b", "c"], "N": 1000, "H": [[0, 0.2, 0.45]], "R": [[0.09]],
           "transition": {"type": "constant", "A": [[0.9, 0, 0.1], [0.1, 0.9, 0], [0, 0.1, 0.9]]}})",
       "y\n1.0\n", "--estimator exact", "more than 200000 count vectors"},
      {"unknown estimator", kTwoStateModel, kGoodLog, "--estimator magic", "magic", 2},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string model = (dir_ / "model.json").string();
    fs::remove(model);
    if (!c.model.empty()) Write("model.json", c.model);
    const std::string log = Write("log.csv", c.log);
    const RunResult r =
        RunRecruit("filter --model " + model + " --log " + log + " --out " + Out() + " " + c.extra);
    EXPECT_EQ(r.exit_code, c.code) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_TRUE(NoOutput());
  }
}

TEST_F(EstimationCli, UnwritableOutputFails) {
  const RunResult r =
      RunRecruit("filter --model " + Write("model.json", kTwoStateModel) + " --log " +
                 Write("log.csv", kGoodLog) + " --out /nonexistent_dir/out.csv");
  EXPECT_EQ(r.exit_code, 4);  // I/O
  EXPECT_NE(r.err.find("cannot write '/nonexistent_dir/out.csv'"), std::string::npos) << r.err;
}

// Issue 12: a log saved with a UTF-8 byte-order mark (spreadsheet exports) reads as without.
TEST_F(EstimationCli, ByteOrderMarkIsAccepted) {
  const std::string model = Write("model.json", kTwoStateModel);
  const RunResult r =
      RunRecruit("filter --model " + model + " --log " +
                 Write("log.csv", "\xEF\xBB\xBF" + std::string(kGoodLog)) + " --out " + Out());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string with_bom = *ReadFile(Out());
  const std::string plain = (dir_ / "plain.csv").string();
  ASSERT_EQ(RunRecruit("filter --model " + model + " --log " + Write("log2.csv", kGoodLog) +
                       " --out " + plain)
                .exit_code,
            0);
  EXPECT_EQ(with_bom, *ReadFile(plain));
  EXPECT_EQ(with_bom.rfind("step,t,updated,", 0), 0u) << with_bom;
}

// Issue 12: --out naming an input (same path, another path to it, a symbolic link to it)
// is refused before anything is read or written; the input is unchanged.
TEST_F(EstimationCli, OutputEqualToAnInputIsRefused) {
  const std::string model = Write("model.json", kTwoStateModel);
  const std::string log = Write("log.csv", kGoodLog);
  fs::create_symlink(log, dir_ / "link.csv");
  const std::string other_path = (dir_ / "." / "log.csv").string();
  for (const std::string& out : {log, other_path, (dir_ / "link.csv").string(), model}) {
    SCOPED_TRACE(out);
    const RunResult r = RunRecruit("filter --model " + model + " --log " + log + " --out " + out);
    EXPECT_EQ(r.exit_code, 2);  // docs/reliability.md
    EXPECT_NE(r.err.find("is the same file as"), std::string::npos) << r.err;
    EXPECT_EQ(*ReadFile(log), kGoodLog);
    EXPECT_EQ(*ReadFile(model), kTwoStateModel);
    EXPECT_TRUE(fs::is_symlink(dir_ / "link.csv"));
  }
}

// Issue 12: a 2 MB cell comes back shortened in the message.
TEST_F(EstimationCli, LongCellIsShortenedInTheMessage) {
  const std::string big(2000000, '7');
  const RunResult r =
      RunRecruit("filter --model " + Write("model.json", kTwoStateModel) + " --log " +
                 Write("log.csv", "t,p_on,p_off,y\n0,0.2,0,1x" + big + "\n") + " --out " + Out());
  EXPECT_EQ(r.exit_code, 3);  // docs/reliability.md
  EXPECT_NE(r.err.find(":2: column 'y': '1x7777"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), 300u);
  EXPECT_TRUE(NoOutput());
}

// The streamed CLI (sparse broadcast predict, shortest round-trip numbers) against the dense
// dynamic-size filter stepped here with the broadcast model's dense matrix: every number of
// every row equal to 1e-12 relative, on a 20-state heating / cooling chain with missing
// measurements; the output numbers read back exactly (to_chars shortest form).
TEST_F(EstimationCli, StreamedRunMatchesTheDenseFilter) {
  const int m = 20;
  estimation::FilterModel f = estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.3);
  f.broadcast = estimation::BroadcastTransitionModel::HeatingChain(m, 0.5);
  f.state_names = f.broadcast.state_names;
  f.H = Eigen::MatrixXd::Zero(1, m);
  for (int i = 1; i < m; ++i) f.H(0, i) = 0.45 * (i <= m / 2 ? i : m - i) / (m / 2);
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0(0) = 60;
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  f.G = Eigen::MatrixXd::Zero(m, 0);
  const std::string model = (dir_ / "model.json").string();
  const Status saved = f.Save(model);
  ASSERT_TRUE(saved.ok()) << saved.error();
  std::string log = "t,p_on,p_off,y\n";
  std::vector<double> p_on, p_off, y;
  for (int k = 0; k < 300; ++k) {
    p_on.push_back(0.001 * ((k * 37) % 300));
    p_off.push_back(0.001 * ((k * 53) % 200));
    y.push_back(k % 7 == 3 ? NAN : 5.0 + 4.0 * std::sin(0.05 * k));
    char line[96];
    std::snprintf(line, sizeof line, "%g,%.3f,%.3f,", 0.5 * k, p_on[k], p_off[k]);
    log += line;
    if (!std::isnan(y[k])) log += std::to_string(y[k]);
    log += "\n";
  }
  const RunResult r =
      RunRecruit("filter --model " + model + " --log " + Write("log.csv", log) + " --out " + Out());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto loaded = estimation::FilterModel::FromJson(model);
  ASSERT_TRUE(loaded.ok());
  auto kf =
      estimation::PopulationKalmanFilter::Create(*loaded, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(kf.ok());
  std::string header;
  const auto rows = ReadCsvNumbers(Out(), &header);
  ASSERT_EQ(rows.size(), 300u);
  for (int k = 0; k < 300; ++k) {
    if (k > 0) kf->Predict(loaded->broadcast.Matrix(p_on[k - 1], p_off[k - 1]));
    if (!std::isnan(y[k]))
      kf->Update(Eigen::VectorXd::Constant(1, std::stod(std::to_string(y[k]))));
    const double scale = 1.0 + kf->covariance().diagonal().cwiseAbs().maxCoeff();
    ASSERT_EQ(rows[k].size(), 3u + 2 * m);
    EXPECT_EQ(rows[k][2], std::isnan(y[k]) ? 0.0 : 1.0);
    for (int i = 0; i < m; ++i) {
      ASSERT_NEAR(rows[k][3 + i], kf->estimate()(i), 1e-12 * 60.0) << "row " << k;
      ASSERT_NEAR(rows[k][3 + m + i], kf->covariance()(i, i), 1e-12 * scale) << "row " << k;
    }
  }
}

}  // namespace file_filter_cli_test
}  // namespace recruit
