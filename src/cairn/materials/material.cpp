#include "cairn/materials/material.hpp"

#include "cairn/materials/elastic_constants.hpp"

namespace cairn {

std::map<std::string, MaterialModelInfo>& material_model_info() {
  static std::map<std::string, MaterialModelInfo> info;
  return info;
}

std::unique_ptr<Material> make_material(const MaterialConfig& cfg) {
  return MaterialRegistry::instance().create("material model", cfg.model, cfg);
}

std::vector<std::string> material_model_names() { return MaterialRegistry::instance().names(); }

KeyDecl material_choice_key(std::string name, std::string default_choice, std::vector<std::string> choices,
                            std::string doc) {
  KeyDecl k;
  k.section = "material";
  k.name = std::move(name);
  k.type = KeyType::string;
  k.default_value = "\"" + default_choice + "\"";
  k.choices = [choices = std::move(choices)] { return choices; };
  k.doc = std::move(doc);
  return k;
}

std::vector<KeyDecl> elastic_constant_keys() {
  auto modulus = [](std::string name, std::string doc) {
    KeyDecl k;
    k.section = "material";
    k.name = std::move(name);
    k.type = KeyType::real;
    k.min = 0.0;
    k.doc = std::move(doc);
    return k;
  };
  std::vector<KeyDecl> keys = {
      modulus("youngs_modulus", "Young's modulus E (pair with poissons_ratio)"),
      modulus("poissons_ratio", "Poisson's ratio nu (pair with youngs_modulus)"),
      modulus("lambda", "Lame's first parameter (pair with shear_modulus)"),
      modulus("shear_modulus", "shear modulus G (pair with lambda or bulk_modulus)"),
      modulus("bulk_modulus", "bulk modulus K (pair with shear_modulus)"),
  };
  keys[1].max = 0.5;
  return keys;
}

std::string check_elastic_constants(const MaterialConfig& cfg) {
  const bool e = cfg.has("youngs_modulus"), nu = cfg.has("poissons_ratio"), l = cfg.has("lambda"),
             g = cfg.has("shear_modulus"), k = cfg.has("bulk_modulus");
  const int pairs = (e && nu) + (l && g) + (k && g);
  const int given = e + nu + l + g + k;
  if (pairs == 1 && given == 2) {
    if (nu && cfg.number("poissons_ratio") >= 0.5) return "poissons_ratio below 0.5";
    return "";
  }
  return "exactly one pair of elastic constants: (youngs_modulus, poissons_ratio), "
         "(lambda, shear_modulus) or (bulk_modulus, shear_modulus)";
}

ElasticConstants elastic_constants(const MaterialConfig& cfg) {
  ElasticConstants c;
  if (cfg.has("youngs_modulus")) {
    const double E = cfg.number("youngs_modulus"), nu = cfg.number("poissons_ratio");
    c.shear = E / (2.0 * (1.0 + nu));
    c.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  } else if (cfg.has("lambda")) {
    c.lambda = cfg.number("lambda");
    c.shear = cfg.number("shear_modulus");
  } else {
    c.shear = cfg.number("shear_modulus");
    c.lambda = cfg.number("bulk_modulus") - 2.0 * c.shear / 3.0;
  }
  return c;
}

}  // namespace cairn
