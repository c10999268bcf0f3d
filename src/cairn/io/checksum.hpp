// A checksum over the content of an HDF5 file, so that a checkpoint changed or damaged after it
// was written is refused instead of silently restarting from wrong data.
//
// The checksum covers every group, dataset and attribute below the root (except the root
// attribute `checksum` that holds it), visited in name order: each object's path, each
// dataset's and attribute's type class, element size, shape and raw bytes (strings by content).
// It is computed from the file after writing, so it does not depend on how the writer laid out
// or buffered the arrays. The hash is 64-bit multiply-xorshift over 8-byte words: any change of
// one word changes it; it is not meant to resist a forger.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>

namespace cairn {

/// The content checksum of the file (or group) `root`.
std::uint64_t h5_content_checksum(hid_t root);

/// Compute the checksum of `root` and store it as its attribute `checksum` (16 hex digits).
void write_content_checksum(hid_t root);

/// Compare the stored checksum with the content of `root`: true when they agree or the file has
/// none (written before checksums); false when they differ. `stored` and `computed` receive the
/// two values as hex text.
bool content_checksum_matches(hid_t root, std::string& stored, std::string& computed);

}  // namespace cairn
