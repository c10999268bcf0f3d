// Zoltan's recursive coordinate bisection (RCB) against Cairn's weighted bisection with kept cuts
// (parallel/decomposition.*) on a moving, two-cost particle field (docs/parallel.md, "Load
// balance"; docs/performance-notes.md). Not part of the build: Zoltan (Debian
// libtrilinos-zoltan-dev) lost the comparison and is not a dependency. Built by hand:
//
//   mpicxx -O2 -std=c++20 -DCAIRN_HAVE_MPI -Isrc -I/usr/include/eigen3 -I/usr/include/trilinos \
//     bench/zoltan_rcb.cpp src/cairn/parallel/decomposition.cpp src/cairn/parallel/comm.cpp \
//     -ltrilinos_zoltan -o /tmp/zoltan_rcb
//   mpirun --oversubscribe --allow-run-as-root -np 3 /tmp/zoltan_rcb
//
// The field: 256 x 128 cells, 2 x 2 particles per cell; a resting block (cost 1) and a block of
// cost 3 that moves left by a quarter cell per step through it, 240 steps. Every step the
// particles go to the owner of their cell; when the cost imbalance (largest rank over the mean)
// exceeds 1 + threshold (0.05) the partition is redone. Printed per method: repartitions,
// particles moved by them (total, most in one), the imbalance right after a repartition (worst)
// and over the steps (mean, worst), and the wall time of a repartition (median over the calls,
// slowest rank). Each particle's cell centre stands for it (Cairn's boxes are whole cells).
#include <zoltan.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cairn/parallel/decomposition.hpp"

using cairn::Comm;
using cairn::Decomposition;
using cairn::IVec;

namespace {

constexpr int NX = 256, NY = 128, STEPS = 240;
constexpr double THRESHOLD = 0.05;

struct Field {
  std::vector<double> x0, y0, speed;
  std::vector<std::int64_t> weight;
  Field() {
    auto block = [&](int x_lo, int x_hi, int y_lo, int y_hi, double v, std::int64_t w) {
      for (int j = 2 * y_lo; j < 2 * y_hi; ++j)
        for (int i = 2 * x_lo; i < 2 * x_hi; ++i) {
          x0.push_back(0.5 * i + 0.25);
          y0.push_back(0.5 * j + 0.25);
          speed.push_back(v);
          weight.push_back(w);
        }
    };
    block(16, 112, 16, 112, 0.0, 1000);
    block(150, 210, 30, 100, -0.25, 3000);
  }
  [[nodiscard]] std::size_t n() const { return x0.size(); }
  [[nodiscard]] IVec<2> cell(std::size_t p, int step) const {
    return IVec<2>(std::clamp(static_cast<int>(x0[p] + speed[p] * step), 0, NX - 1),
                   std::clamp(static_cast<int>(y0[p]), 0, NY - 1));
  }
};

struct Owned {  // this rank's particles, for the Zoltan callbacks
  const Field* field = nullptr;
  int step = 0;
  std::vector<std::size_t> ids;
};

int num_obj(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<int>(static_cast<Owned*>(data)->ids.size());
}

void obj_list(void* data, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int, float* w, int* ierr) {
  const auto* o = static_cast<Owned*>(data);
  for (std::size_t k = 0; k < o->ids.size(); ++k) {
    gids[k] = static_cast<ZOLTAN_ID_TYPE>(o->ids[k]);
    lids[k] = static_cast<ZOLTAN_ID_TYPE>(k);
    w[k] = static_cast<float>(o->field->weight[o->ids[k]]);
  }
  *ierr = ZOLTAN_OK;
}

int num_geom(void*, int* ierr) {
  *ierr = ZOLTAN_OK;
  return 2;
}

void geom_multi(void* data, int, int, int n, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int, double* xy, int* ierr) {
  const auto* o = static_cast<Owned*>(data);
  for (int k = 0; k < n; ++k) {
    const IVec<2> c = o->field->cell(o->ids[lids[k]], o->step);
    xy[2 * k] = c[0] + 0.5;
    xy[2 * k + 1] = c[1] + 0.5;
  }
  *ierr = ZOLTAN_OK;
}

struct Tally {
  int repartitions = 0;
  long long moved = 0, most = 0;
  double worst_after = 1.0, worst = 1.0, sum = 0.0;
  std::vector<double> seconds;
};

double imbalance(const Field& f, const std::vector<int>& owner, int ranks) {
  std::vector<std::int64_t> cost(static_cast<std::size_t>(ranks), 0);
  std::int64_t total = 0;
  for (std::size_t p = 0; p < f.n(); ++p) {
    cost[static_cast<std::size_t>(owner[p])] += f.weight[p];
    total += f.weight[p];
  }
  return static_cast<double>(*std::max_element(cost.begin(), cost.end())) * ranks / static_cast<double>(total);
}

double slowest(double t0) {
  double t = MPI_Wtime() - t0;
  MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return t;
}

// Every rank follows every particle (cheap here) but hands the partitioner only its own.
template <class Partitioner>
Tally run(const Field& f, const Comm& comm, Partitioner&& partitioner) {
  Tally t;
  std::vector<int> owner(f.n());
  auto mine = [&](int step) {
    std::vector<std::size_t> ids;
    for (std::size_t p = 0; p < f.n(); ++p)
      if (owner[p] == comm.rank()) ids.push_back(p);
    return ids;
  };
  for (std::size_t p = 0; p < f.n(); ++p) owner[p] = static_cast<int>(p % static_cast<std::size_t>(comm.size()));
  partitioner.partition(mine(0), 0, true);
  for (std::size_t p = 0; p < f.n(); ++p) owner[p] = partitioner.owner(f.cell(p, 0));
  for (int step = 1; step <= STEPS; ++step) {
    for (std::size_t p = 0; p < f.n(); ++p) owner[p] = partitioner.owner(f.cell(p, step));  // migration
    double imb = imbalance(f, owner, comm.size());
    if (imb > 1.0 + THRESHOLD) {
      const std::vector<int> before = owner;
      comm.barrier();
      const double t0 = MPI_Wtime();
      partitioner.partition(mine(step), step, false);
      t.seconds.push_back(slowest(t0));
      long long moved = 0;
      for (std::size_t p = 0; p < f.n(); ++p) {
        owner[p] = partitioner.owner(f.cell(p, step));
        moved += owner[p] != before[p];
      }
      ++t.repartitions;
      t.moved += moved;
      t.most = std::max(t.most, moved);
      imb = imbalance(f, owner, comm.size());
      t.worst_after = std::max(t.worst_after, imb);
    }
    t.worst = std::max(t.worst, imb);
    t.sum += imb;
  }
  return t;
}

struct CairnBisection {
  const Field* f;
  const Comm* comm;
  bool keep;  // rebalanced() (kept cuts) or a fresh bisect()
  Decomposition<2> d;
  void partition(const std::vector<std::size_t>& ids, int step, bool first) {
    std::vector<IVec<2>> cells;
    std::vector<std::int64_t> w;
    for (std::size_t p : ids) {
      cells.push_back(f->cell(p, step));
      w.push_back(f->weight[p]);
    }
    d = first || !keep ? Decomposition<2>::bisect(*comm, IVec<2>(NX, NY), {false, false}, cells, w)
                       : d.rebalanced(*comm, cells, w, THRESHOLD / 4.0);  // threshold / (2 depth), 2-3 ranks
  }
  [[nodiscard]] int owner(const IVec<2>& c) const { return d.owner(c); }
};

struct ZoltanRcb {
  const Field* f;
  Owned data;
  Zoltan_Struct* zz = nullptr;
  ZoltanRcb(const Field* field, const char* tolerance) : f(field) {
    data.field = field;
    zz = Zoltan_Create(MPI_COMM_WORLD);
    const char* params[][2] = {{"LB_METHOD", "RCB"},       {"NUM_GID_ENTRIES", "1"}, {"NUM_LID_ENTRIES", "1"},
                               {"OBJ_WEIGHT_DIM", "1"},    {"RETURN_LISTS", "NONE"}, {"KEEP_CUTS", "1"},
                               {"RCB_REUSE", "1"},         {"RCB_RECTILINEAR_BLOCKS", "1"},
                               {"IMBALANCE_TOL", tolerance}, {"DEBUG_LEVEL", "0"}};
    for (auto& p : params) Zoltan_Set_Param(zz, p[0], p[1]);
    Zoltan_Set_Num_Obj_Fn(zz, num_obj, &data);
    Zoltan_Set_Obj_List_Fn(zz, obj_list, &data);
    Zoltan_Set_Num_Geom_Fn(zz, num_geom, &data);
    Zoltan_Set_Geom_Multi_Fn(zz, geom_multi, &data);
  }
  ~ZoltanRcb() { Zoltan_Destroy(&zz); }
  void partition(const std::vector<std::size_t>& ids, int step, bool) {
    data.ids = ids;
    data.step = step;
    int changes = 0, ngid = 0, nlid = 0, nimp = 0, nexp = 0;
    ZOLTAN_ID_PTR ig = nullptr, il = nullptr, eg = nullptr, el = nullptr;
    int *ip = nullptr, *ipart = nullptr, *ep = nullptr, *epart = nullptr;
    if (Zoltan_LB_Partition(zz, &changes, &ngid, &nlid, &nimp, &ig, &il, &ip, &ipart, &nexp, &eg, &el, &ep, &epart) !=
        ZOLTAN_OK)
      MPI_Abort(MPI_COMM_WORLD, 1);
    Zoltan_LB_Free_Part(&ig, &il, &ip, &ipart);
    Zoltan_LB_Free_Part(&eg, &el, &ep, &epart);
  }
  [[nodiscard]] int owner(const IVec<2>& c) const {
    double xy[2] = {c[0] + 0.5, c[1] + 0.5};
    int proc = 0;
    Zoltan_LB_Point_Assign(zz, xy, &proc);
    return proc;
  }
};

void report(const Comm& comm, const char* name, const Tally& t) {
  if (!comm.is_root()) return;
  std::vector<double> s = t.seconds;
  std::sort(s.begin(), s.end());
  std::printf("%-34s %4d repartitions, moved %8lld (most %6lld), imbalance after <= %.4f, steps mean %.4f max "
              "%.4f, %.2f ms per repartition\n",
              name, t.repartitions, t.moved, t.most, t.worst_after, t.sum / STEPS, t.worst,
              s.empty() ? 0.0 : 1e3 * s[s.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  float version = 0.0f;
  Zoltan_Initialize(argc, argv, &version);
  {
    const Comm comm = Comm::world();
    const Field f;
    if (comm.is_root()) std::printf("%zu particles, %d ranks, threshold %.2f\n", f.n(), comm.size(), THRESHOLD);
    report(comm, "cairn bisection, kept cuts", run(f, comm, CairnBisection{&f, &comm, true, {}}));
    report(comm, "cairn bisection, fresh each time", run(f, comm, CairnBisection{&f, &comm, false, {}}));
    for (const char* tol : {"1.1", "1.01"}) {
      ZoltanRcb z(&f, tol);
      report(comm, (std::string("zoltan rcb, reuse, tol ") + tol).c_str(), run(f, comm, z));
    }
  }
  MPI_Finalize();
  return 0;
}
