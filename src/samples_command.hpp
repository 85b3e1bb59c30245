#pragma once
// `mcrt samples`: N independent samples of one light's strategy, as seen from
// a point with a normal, written as CSV (docs/cli.md).
#include <cstdint>
#include <string>

#include "input_file.hpp"

namespace mcrt::cli {

struct samples_options {
  std::string scene, output, light_sampling, from, normal, ellipse_map = "parallel";
  long long light = -1;
  long long n = 100000;
  std::uint64_t seed = 0;
  std::string max_input_size;  // --max-input-size as given
  std::uint64_t max_input_bytes = io::default_max_input_bytes;  // ... as bytes
};

// Throws input_error (exit status 2) for bad arguments, before writing anything.
int run_samples(const samples_options& opt);

}  // namespace mcrt::cli
