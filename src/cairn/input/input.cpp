// The input validator: TOML (toml++) + `--set` overrides -> Config, checking every key against its
// declaration in input/schema.cpp. Errors name file:line (toml++ source positions) or the `--set`
// text, the key, what was expected and what was found.
#include "cairn/input/loader.hpp"

namespace cairn {

using namespace input_detail;

Config load_config_string(const std::string& toml_text, const std::string& name,
                          const std::vector<std::string>& overrides) {
  const std::string file = name.empty() ? std::string("<input>") : name;
  toml::table root;
  try {
    root = toml::parse(toml_text, file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, static_cast<int>(e.source().begin.line), "", "valid TOML",
                     std::string(e.description()));
  }
  Loader loader(file);
  Config cfg = loader.load(root, overrides);
  cfg.source_file = name;
  return cfg;
}

Config load_config(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "", "a readable input file", std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  Config cfg = load_config_string(text.str(), path, overrides);
  // A relative output folder from the file (or the default out/<stem>) lies next to the input
  // file; one given with --set is relative to the working directory, as typed.
  bool from_command_line = false;
  for (const auto& o : overrides)
    from_command_line = from_command_line || trim(o.substr(0, o.find('='))) == "output.directory";
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!from_command_line && !folder.empty() && std::filesystem::path(cfg.output.directory).is_relative()) {
    cfg.output.directory = (folder / cfg.output.directory).lexically_normal().string();
    cfg.resolved_toml = config_to_toml(cfg);
  }
  return cfg;
}

}  // namespace cairn
