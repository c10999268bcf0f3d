// Isotropic elastic constants from whichever pair the input gives:
// (youngs_modulus, poissons_ratio), (lambda, shear_modulus) or (bulk_modulus, shear_modulus).
#pragma once

#include <string>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/config/keys.hpp"

namespace cairn {

struct ElasticConstants {
  double lambda = 0.0;  ///< Lame's first parameter
  double shear = 0.0;   ///< shear modulus G = mu
  [[nodiscard]] double bulk() const { return lambda + 2.0 * shear / 3.0; }
  [[nodiscard]] double youngs() const { return shear * (3.0 * lambda + 2.0 * shear) / (lambda + shear); }
};

/// A string key of a [[material]] with a fixed list of choices (e.g. a model's `form`).
KeyDecl material_choice_key(std::string name, std::string default_choice, std::vector<std::string> choices,
                            std::string doc);
/// The key declarations for the three pairs (none has a default).
std::vector<KeyDecl> elastic_constant_keys();
/// "" when exactly one complete pair is given, else a message saying what is wrong.
std::string check_elastic_constants(const MaterialConfig& cfg);
ElasticConstants elastic_constants(const MaterialConfig& cfg);

}  // namespace cairn
