// SHA-256 digest (FIPS 180-4, computed by OpenSSL), used to fingerprint the resolved input in output files.
#pragma once

#include <string>
#include <string_view>

namespace cairn {

/// SHA-256 of `data` as 64 lowercase hex digits (FIPS 180-4 Sec. 6.2).
[[nodiscard]] std::string sha256_hex(std::string_view data);

}  // namespace cairn
