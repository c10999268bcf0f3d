// The input the input-layer tests edit, and what they ask of a reading that must fail.
#pragma once

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "cairn/input/input.hpp"

namespace cairn::test {

// A valid 2D input; tests edit one line of it, so the line numbers in the comments hold.
inline const std::string base = R"toml([simulation]
title = "two blocks"
dimension = 2
end_time = 2.0e-3
cfl = 0.4

[grid]
origin = [0.0, 0.0]
extent = [0.12, 0.04]
cell_size = 1.0e-3

[method]
shape = "bspline2"
update = "flip"

[[material]]
name = "rubber"
model = "linear_elastic"
density = 1500.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[body]]
name = "left"
material = "rubber"
shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }
velocity = [8.165, 0.0]

[boundary]
x_min = "fixed"
)toml";
// Lines: 1 [simulation], 3 dimension, 5 cfl, 8 origin, 10 cell_size, 13 shape, 16 [[material]],
// 18 model, 23 [[body]], 25 material, 26 shape, 29 [boundary], 30 x_min.

/// `base` with the first occurrence of `from` replaced by `to`.
inline std::string with(const std::string& from, const std::string& to, std::string text = base) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the input";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The InputError that loading `text` raises (a test failure when none is raised).
inline std::optional<InputError> error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    load_config_string(text, "case.toml", overrides);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an InputError";
  return std::nullopt;
}

inline std::string message(const std::optional<InputError>& e) { return e ? e->what() : ""; }


}  // namespace cairn::test
