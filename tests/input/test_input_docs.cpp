// docs/input.md is generated from the key declarations; this test keeps it from going stale.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "cairn/input/schema.hpp"

namespace cairn {
namespace {

TEST(InputDocs, InputMdMatchesTheDeclarations) {
  const std::string path = std::string(CAIRN_SOURCE_DIR) + "/docs/input.md";
  const std::string generated = keys_text(true);
  // CAIRN_UPDATE_DOCS=1 rewrites the file instead of comparing (e.g. before the CLI exists).
  if (std::getenv("CAIRN_UPDATE_DOCS") != nullptr) {
    std::ofstream(path, std::ios::binary) << generated;
    GTEST_SKIP() << "rewrote " << path;
  }
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << path << " is missing; generate it with\n"
                  << "  build/release/cairn keys --markdown > docs/input.md";
  std::ostringstream text;
  text << in.rdbuf();
  EXPECT_TRUE(text.str() == generated)
      << "docs/input.md is out of date with the key declarations (input/schema.cpp, the registries "
         "and the material models' keys); regenerate it with\n"
         "  build/release/cairn keys --markdown > docs/input.md\n"
         "(or run this test with CAIRN_UPDATE_DOCS=1) and commit the result.";
}

TEST(InputDocs, KeysFitA100ColumnTerminal) {
  std::istringstream text(keys_text(false));
  std::string line;
  int n = 0;
  while (std::getline(text, line)) {
    ++n;
    EXPECT_LE(line.size(), 100u) << "line " << n << " of `cairn keys`: " << line;
  }
  EXPECT_GT(n, 100);
  // Every documented key is still there (its name starts a row).
  EXPECT_NE(keys_text(false).find("\n  checkpoint_wall_interval  "), std::string::npos);
}

}  // namespace
}  // namespace cairn
