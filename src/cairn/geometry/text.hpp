// Small text helpers of the geometry room's file readers (outline.cpp, point_set.cpp).
#pragma once

#include <string>

namespace cairn::geometry {

/// `s` without leading and trailing blanks (spaces, tabs, carriage returns).
inline std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

}  // namespace cairn::geometry
