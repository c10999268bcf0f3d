#include "cairn/parallel/comm.hpp"

#include <climits>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace cairn {

#ifdef CAIRN_HAVE_MPI

namespace {

int checked_count(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error("MPI message of " + std::to_string(bytes) + " bytes exceeds 2 GiB");
  return static_cast<int>(bytes);
}

}  // namespace

bool built_with_mpi() { return true; }

Comm Comm::world() {
  Comm c;
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  if (!initialised || finalised) return c;
  MPI_Comm_rank(MPI_COMM_WORLD, &c.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &c.size_);
  return c;
}

void Comm::barrier() const {
  if (parallel()) MPI_Barrier(MPI_COMM_WORLD);
}

void Comm::sum(std::int64_t* values, int n) const {
  if (parallel()) MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
}

void Comm::max(double* values, int n) const {
  if (parallel()) MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

void Comm::max(std::int64_t* values, int n) const {
  if (parallel()) MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
}

void Comm::min(std::int64_t* values, int n) const {
  if (parallel()) MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
}

std::int64_t Comm::exclusive_prefix(std::int64_t v) const {
  if (!parallel()) return 0;
  std::int64_t out = 0;
  MPI_Exscan(&v, &out, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  return rank_ == 0 ? 0 : out;
}

std::vector<std::int64_t> Comm::all_gather(std::int64_t v) const {
  std::vector<std::int64_t> out(static_cast<std::size_t>(size_), v);
  if (parallel()) MPI_Allgather(&v, 1, MPI_INT64_T, out.data(), 1, MPI_INT64_T, MPI_COMM_WORLD);
  return out;
}

void Comm::broadcast(void* data, std::size_t bytes, int root) const {
  if (parallel()) MPI_Bcast(data, checked_count(bytes), MPI_BYTE, root, MPI_COMM_WORLD);
}

void Comm::broadcast(std::string& text, int root) const {
  if (!parallel()) return;
  std::int64_t n = static_cast<std::int64_t>(text.size());
  broadcast(&n, sizeof n, root);
  text.resize(static_cast<std::size_t>(n));
  if (n > 0) broadcast(text.data(), text.size(), root);
}

Comm::Buffers Comm::exchange(const std::vector<int>& neighbours, const Buffers& send) const {
  const std::size_t k = neighbours.size();
  Buffers recv(k);
  if (!parallel() || k == 0) return recv;
  // A round of sizes, then the data as exchange_sized sends it.
  constexpr int tag_size = 7101;
  std::vector<std::int64_t> send_size(k), recv_size(k);
  std::vector<MPI_Request> requests;
  requests.reserve(2 * k);
  for (std::size_t i = 0; i < k; ++i) {
    send_size[i] = static_cast<std::int64_t>(send[i].size());
    requests.emplace_back();
    MPI_Irecv(&recv_size[i], 1, MPI_INT64_T, neighbours[i], tag_size, MPI_COMM_WORLD, &requests.back());
    requests.emplace_back();
    MPI_Isend(&send_size[i], 1, MPI_INT64_T, neighbours[i], tag_size, MPI_COMM_WORLD, &requests.back());
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  for (std::size_t i = 0; i < k; ++i) recv[i].resize(static_cast<std::size_t>(recv_size[i]));
  exchange_sized(neighbours, send, recv);
  return recv;
}

void Comm::exchange_sized(const std::vector<int>& neighbours, const Buffers& send, Buffers& recv) const {
  const std::size_t k = neighbours.size();
  if (!parallel() || k == 0) return;
  constexpr int tag = 7103;
  std::vector<MPI_Request> requests;
  requests.reserve(2 * k);
  for (std::size_t i = 0; i < k; ++i) {
    if (!recv[i].empty()) {
      requests.emplace_back();
      MPI_Irecv(recv[i].data(), checked_count(recv[i].size()), MPI_BYTE, neighbours[i], tag, MPI_COMM_WORLD,
                &requests.back());
    }
    if (!send[i].empty()) {
      requests.emplace_back();
      MPI_Isend(send[i].data(), checked_count(send[i].size()), MPI_BYTE, neighbours[i], tag, MPI_COMM_WORLD,
                &requests.back());
    }
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
}

Comm::Buffers Comm::all_to_all(const Buffers& send) const {
  const auto p = static_cast<std::size_t>(size_);
  Buffers recv(p);
  if (!parallel()) {
    recv[0] = send[0];
    return recv;
  }
  std::vector<int> send_count(p), recv_count(p), send_offset(p, 0), recv_offset(p, 0);
  for (std::size_t r = 0; r < p; ++r) send_count[r] = checked_count(send[r].size());
  MPI_Alltoall(send_count.data(), 1, MPI_INT, recv_count.data(), 1, MPI_INT, MPI_COMM_WORLD);
  std::size_t send_total = 0, recv_total = 0;
  for (std::size_t r = 0; r < p; ++r) {
    send_offset[r] = checked_count(send_total);
    recv_offset[r] = checked_count(recv_total);
    send_total += static_cast<std::size_t>(send_count[r]);
    recv_total += static_cast<std::size_t>(recv_count[r]);
  }
  std::vector<char> send_all(send_total), recv_all(recv_total);
  for (std::size_t r = 0; r < p; ++r)
    if (!send[r].empty()) std::memcpy(send_all.data() + send_offset[r], send[r].data(), send[r].size());
  MPI_Alltoallv(send_all.data(), send_count.data(), send_offset.data(), MPI_BYTE, recv_all.data(), recv_count.data(),
                recv_offset.data(), MPI_BYTE, MPI_COMM_WORLD);
  for (std::size_t r = 0; r < p; ++r)
    recv[r].assign(recv_all.begin() + recv_offset[r], recv_all.begin() + recv_offset[r] + recv_count[r]);
  return recv;
}

void Comm::abort(int code) const {
  if (parallel()) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

namespace {

/// Whether an MPI launcher (mpirun/mpiexec of Open MPI or MPICH, Slurm's srun with PMI/PMIx)
/// started this process: only then is MPI initialised, so that a plain `cairn run` of an MPI
/// build stays a serial run with no MPI start-up cost.
bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  if (!launched_by_mpi()) return;
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
}

MpiSession::~MpiSession() {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  if (initialised && !finalised) MPI_Finalize();
}

#else  // no MPI: one rank

bool built_with_mpi() { return false; }
Comm Comm::world() { return Comm(); }
void Comm::barrier() const {}
void Comm::sum(std::int64_t*, int) const {}
void Comm::max(double*, int) const {}
void Comm::max(std::int64_t*, int) const {}
void Comm::min(std::int64_t*, int) const {}
std::int64_t Comm::exclusive_prefix(std::int64_t) const { return 0; }
std::vector<std::int64_t> Comm::all_gather(std::int64_t v) const { return {v}; }
void Comm::broadcast(void*, std::size_t, int) const {}
void Comm::broadcast(std::string&, int) const {}
Comm::Buffers Comm::exchange(const std::vector<int>& neighbours, const Buffers&) const {
  return Buffers(neighbours.size());
}
void Comm::exchange_sized(const std::vector<int>&, const Buffers&, Buffers&) const {}
Comm::Buffers Comm::all_to_all(const Buffers& send) const { return Buffers{send.at(0)}; }
void Comm::abort(int code) const { std::exit(code); }
MpiSession::MpiSession(int*, char***) {}
MpiSession::~MpiSession() = default;

#endif

}  // namespace cairn
