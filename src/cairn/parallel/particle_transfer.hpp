// Moving particles between ranks and within a rank's arrays, through Particles::for_each_array
// so that every per-particle array travels (docs/parallel.md, "Particle migration").
//
// Buffers are array-major: the selected particles' positions, then their reference positions,
// ..., then their state variables; the receiver knows the count from the buffer size and the
// bytes per particle (sender and receiver store the same arrays: the same run).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "cairn/particles/particles.hpp"

namespace cairn {

/// Bytes one particle takes in a transfer buffer.
template <int D>
std::size_t particle_bytes(const Particles<D>& particles) {
  std::size_t bytes = 0;
  particles.for_each_array([&](const auto& array, int width) {
    bytes += static_cast<std::size_t>(width) * sizeof(typename std::decay_t<decltype(array)>::value_type);
  });
  return bytes;
}

/// Append `width` entries per listed index of `values` to `out`.
template <class T, class Index>
void pack_values(const std::vector<T>& values, int width, const std::vector<Index>& indices, std::vector<char>& out) {
  if (width == 0) return;
  const std::size_t row = static_cast<std::size_t>(width) * sizeof(T);
  std::size_t at = out.size();
  out.resize(at + row * indices.size());
  for (Index p : indices) {
    std::memcpy(out.data() + at, values.data() + static_cast<std::size_t>(p) * width, row);
    at += row;
  }
}

/// Copy `count` particles' entries from `in` (at byte `offset`, advanced) into values[first ...].
template <class T>
void unpack_values(std::vector<T>& values, int width, std::size_t first, std::size_t count, const std::vector<char>& in,
                   std::size_t& offset) {
  if (width == 0 || count == 0) return;
  const std::size_t bytes = count * static_cast<std::size_t>(width) * sizeof(T);
  if (offset + bytes > in.size()) throw std::runtime_error("particle transfer: short buffer");
  std::memcpy(static_cast<void*>(values.data() + first * static_cast<std::size_t>(width)), in.data() + offset, bytes);
  offset += bytes;
}

/// Append the listed particles of `particles` to `out`, every array.
template <int D, class Index>
void pack_particles(const Particles<D>& particles, const std::vector<Index>& indices, std::vector<char>& out) {
  particles.for_each_array([&](const auto& array, int width) { pack_values(array, width, indices, out); });
}

/// Append the particles in `in` (packed by pack_particles) to `particles`; returns their count.
template <int D>
std::size_t unpack_particles(Particles<D>& particles, const std::vector<char>& in) {
  const std::size_t bytes = particle_bytes(particles);
  if (bytes == 0 || in.size() % bytes != 0) throw std::runtime_error("particle transfer: buffer size mismatch");
  const std::size_t count = in.size() / bytes, first = particles.n();
  std::size_t offset = 0;
  particles.for_each_array([&](auto& array, int width) {
    array.resize((first + count) * static_cast<std::size_t>(width));
    unpack_values(array, width, first, count, in, offset);
  });
  return count;
}

/// Reorder the particles: particle k becomes the old particle order[k] (order may also drop
/// particles by listing fewer).
template <int D>
void reorder_particles(Particles<D>& particles, const std::vector<std::int32_t>& order) {
  particles.for_each_array([&](auto& array, int width) {
    if (width == 0) return;
    using T = typename std::decay_t<decltype(array)>::value_type;
    std::vector<T> out(order.size() * static_cast<std::size_t>(width));
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int w = 0; w < width; ++w)
        out[k * width + w] = array[static_cast<std::size_t>(order[k]) * width + w];
    array.swap(out);
  });
}

/// Reorder the particles in place (no second copy of any array): particle k becomes the old
/// particle order[k], `order` a permutation of 0 .. n-1. Each cycle of the permutation is walked
/// once per array, marked in a bit per particle.
template <int D>
void permute_particles(Particles<D>& particles, const std::vector<std::int32_t>& order) {
  const std::size_t n = order.size();
  std::vector<bool> done(n);
  particles.for_each_array([&](auto& array, int width) {
    if (width == 0) return;
    using T = typename std::decay_t<decltype(array)>::value_type;
    const auto w = static_cast<std::size_t>(width);
    std::vector<T> held(w);
    done.assign(n, false);
    for (std::size_t start = 0; start < n; ++start) {
      if (done[start]) continue;
      std::copy_n(array.begin() + static_cast<std::ptrdiff_t>(start * w), w, held.begin());
      std::size_t j = start;
      for (;;) {
        done[j] = true;
        const auto from = static_cast<std::size_t>(order[j]);
        if (from == start) break;
        std::copy_n(array.begin() + static_cast<std::ptrdiff_t>(from * w), w, array.begin() + static_cast<std::ptrdiff_t>(j * w));
        j = from;
      }
      std::copy_n(held.begin(), w, array.begin() + static_cast<std::ptrdiff_t>(j * w));
    }
  });
}

/// Storage indices of the particles in increasing id, into `by_id` (its capacity reused; ids
/// 0 .. n-1, a serial run's, are placed directly; any other numbering is sorted).
template <int D>
void storage_in_id_order(const Particles<D>& particles, std::vector<std::int32_t>& by_id) {
  const std::size_t n = particles.n();
  by_id.assign(n, -1);
  bool dense = true;
  for (std::size_t k = 0; k < n && dense; ++k) {
    const std::int64_t id = particles.id[k];
    dense = id >= 0 && static_cast<std::size_t>(id) < n && by_id[static_cast<std::size_t>(id)] < 0;
    if (dense) by_id[static_cast<std::size_t>(id)] = static_cast<std::int32_t>(k);
  }
  if (!dense) {
    for (std::size_t k = 0; k < n; ++k) by_id[k] = static_cast<std::int32_t>(k);
    std::sort(by_id.begin(), by_id.end(), [&](std::int32_t a, std::int32_t b) { return particles.id[a] < particles.id[b]; });
  }
}

/// Keep the first n particles.
template <int D>
void truncate_particles(Particles<D>& particles, std::size_t n) {
  particles.for_each_array([&](auto& array, int width) { array.resize(n * static_cast<std::size_t>(width)); });
}

}  // namespace cairn
