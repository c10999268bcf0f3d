// Reading an input file: TOML text + `--set` overrides -> a validated, fully resolved Config.
//
// Every key is checked against its declaration (io/schema.hpp): unknown keys, wrong types,
// out-of-range values, bad choices and inconsistent combinations all throw InputError naming the
// file and line (or the `--set` text), the key, what was expected and what was found.
#pragma once

#include <string>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/config/errors.hpp"

namespace cairn {

/// Load, override and validate the input file at `path`. `overrides` are `section.key=value`
/// texts from `cairn run FILE --set section.key=value`: the value is read as a TOML value
/// (`method.order=4`, `grid.origin=[0,0]`) or, when it is not one, as a plain string
/// (`method.update=fmpm`); [[material]] / [[body]] entries are addressed by index from 0
/// (`material.0.density` or `material[0].density`). Overrides apply in order.
/// Throws InputError for any invalid input, including a file that cannot be read.
Config load_config(const std::string& path, const std::vector<std::string>& overrides = {});

/// As load_config(), for TOML text held in memory; `name` stands for the file name in error
/// messages, in Config::source_file and in the default output directory (out/<stem of name>).
Config load_config_string(const std::string& toml_text, const std::string& name,
                          const std::vector<std::string>& overrides = {});

/// The TOML text of a validated config with every key written out (Config::resolved_toml is
/// this text). Reading it back with load_config_string() gives the same Config.
std::string config_to_toml(const Config& config);

}  // namespace cairn
