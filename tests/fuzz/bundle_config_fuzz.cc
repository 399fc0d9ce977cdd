// Fuzz target: the plugin's MJCF <config> parser (BundleConfig::FromPairs, which the recruit.sma
// instance calls with one value per key, "" for an unset key; and FromText). A configuration that
// validates must give a bundle that resets, switches, advances and reports a tension.
//
// Input: byte 0 even: the rest is FromText's "key=value ..." text; odd: the rest holds one value
// per line, given to the keys in BundleConfig::Keys() order (as the plugin reads MJCF).
// Byte 1 picks the timestep.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "plugin/bundle.h"
#include "plugin/bundle_config.h"

using recruit::sma::BundleConfig;
using recruit::sma::SmaBundle;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<std::string> kKeys = BundleConfig::Keys();
  if (size < 2) return 0;
  const std::string rest(reinterpret_cast<const char*>(data) + 2, size - 2);
  auto parse = [&]() -> recruit::Result<BundleConfig> {
    if (data[0] % 2 == 0) return BundleConfig::FromText("fuzz", rest);
    std::vector<std::pair<std::string, std::string>> pairs;
    size_t start = 0;
    for (const std::string& key : kKeys) {
      size_t end = start <= rest.size() ? rest.find('\n', start) : std::string::npos;
      if (end == std::string::npos) end = rest.size();
      pairs.emplace_back(key, start <= rest.size() ? rest.substr(start, end - start) : "");
      start = end + 1;
    }
    return BundleConfig::FromPairs("fuzz", "recruit.sma actuator 'fuzz': config ", pairs);
  };
  const recruit::Result<BundleConfig> cfg = parse();
  if (!cfg.ok()) return 0;
  static const double kTimesteps[] = {1e-4, 2e-3, 0.05};
  const double dt = kTimesteps[data[1] % 3];
  auto bundle = SmaBundle::Create(*cfg, dt);
  if (!bundle.ok() || cfg->units > 5000) return 0;  // large bundles: parsing is what is fuzzed
  std::vector<double> s(bundle->state_size());
  const double stretch = cfg->unit.prestretch;
  bundle->Reset(s.data(), 7, stretch);
  if (!bundle->Broadcast(s.data(), 0.5, 0.25, stretch).ok()) __builtin_trap();
  for (int k = 0; k < 4; ++k) bundle->Advance(s.data(), stretch, dt);
  volatile double sink = bundle->Tension(s.data(), stretch) + bundle->MeanTemperature(s.data());
  (void)sink;
  return 0;
}
