// release = "separation" (docs/contact.md, "Release"): the record of field pairs held in contact,
// keyed by the node's domain index, written to checkpoints and shared at repartitions.
#include <algorithm>
#include <cstring>

#include "cairn/contact/contact.hpp"

namespace cairn {

template <int D>
std::int64_t Contact<D>::pair_key(std::int32_t node, int a, int b) const {
  const IVec<D> j = grid_->multi_index(node);
  const int g = grid_->ghost_layers();
  std::int64_t index = 0;
  for (int axis = 0; axis < D; ++axis) index = index * (grid_->n_cells()[axis] + 1 + 2 * g) + (j[axis] + g);
  const std::int64_t nf = n_fields() + 1;
  return (index * nf + a) * nf + (b < 0 ? nf - 1 : b);
}

template <int D>
std::int64_t Contact<D>::record_key_end() const {
  std::int64_t nodes = 1;
  for (int axis = 0; axis < D; ++axis) nodes *= grid_->n_cells()[axis] + 1 + 2 * grid_->ghost_layers();
  const std::int64_t nf = n_fields() + 1;
  return nodes * nf * nf;
}

template <int D>
std::vector<std::int64_t> Contact<D>::record() const {
  std::vector<std::int64_t> keys(in_contact_.begin(), in_contact_.end());
  std::sort(keys.begin(), keys.end());
  return keys;
}

template <int D>
void Contact<D>::restore_record(const std::vector<std::int64_t>& keys) {
  in_contact_.clear();
  if (release_by_separation_) in_contact_.insert(keys.begin(), keys.end());
}

template <int D>
void Contact<D>::share_record(const Comm& comm) {
  if (!release_by_separation_ || !comm.parallel()) return;
  const std::vector<std::int64_t> mine = record();
  std::vector<char> bytes(mine.size() * sizeof(std::int64_t));
  if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
  const Comm::Buffers received = comm.all_to_all(Comm::Buffers(static_cast<std::size_t>(comm.size()), bytes));
  for (const std::vector<char>& from : received) {
    std::vector<std::int64_t> keys(from.size() / sizeof(std::int64_t));
    if (!keys.empty()) std::memcpy(keys.data(), from.data(), keys.size() * sizeof(std::int64_t));
    in_contact_.insert(keys.begin(), keys.end());
  }
}

#define CAIRN_CONTACT_RECORD(D)                                                                   \
  template std::int64_t Contact<D>::pair_key(std::int32_t, int, int) const;                     \
  template std::int64_t Contact<D>::record_key_end() const;                                     \
  template std::vector<std::int64_t> Contact<D>::record() const;                                \
  template void Contact<D>::restore_record(const std::vector<std::int64_t>&);                   \
  template void Contact<D>::share_record(const Comm&);
CAIRN_CONTACT_RECORD(1)
CAIRN_CONTACT_RECORD(2)
CAIRN_CONTACT_RECORD(3)
#undef CAIRN_CONTACT_RECORD

}  // namespace cairn
