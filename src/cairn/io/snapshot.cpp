#include "cairn/io/snapshot.hpp"

#include <Eigen/LU>
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "cairn/io/atomic_file.hpp"
#include "cairn/io/hdf5_util.hpp"

namespace cairn {

namespace fs = std::filesystem;

namespace {

/// Escape the XML special characters of a text used in an attribute value or element body.
std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string join(const std::vector<std::size_t>& dims) {
  std::string s;
  for (std::size_t i = 0; i < dims.size(); ++i) s += (i > 0 ? " " : "") + std::to_string(dims[i]);
  return s;
}

/// Append an HDF DataItem referencing `file`:`dataset`.
void hdf_item(fmt::memory_buffer& out, const std::string& indent, const std::string& dims,
              bool integer, const std::string& file, const std::string& dataset) {
  fmt::format_to(std::back_inserter(out),
                 "{}<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">"
                 "snapshots/{}:{}</DataItem>\n",
                 indent, dims, integer ? "Int" : "Float", integer ? 4 : 8, xml_escape(file),
                 dataset);
}

void attribute(fmt::memory_buffer& out, const std::string& name, const char* type,
               const std::string& dims, bool integer, const std::string& file,
               const std::string& dataset) {
  fmt::format_to(std::back_inserter(out),
                 "        <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n", name, type);
  hdf_item(out, "          ", dims, integer, file, dataset);
  out.append(std::string_view("        </Attribute>\n"));
}

const char* xdmf_header() {
  return "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
         "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
         "  <Domain>\n";
}

/// `values` in the file's particle order: the array itself, or with an `order` a copy in it.
template <class T>
const T* arranged(const std::vector<T>& values, const std::vector<std::int32_t>* order, std::vector<T>& copy) {
  if (!order) return values.data();
  copy.resize(order->size());
  for (std::size_t p = 0; p < order->size(); ++p) copy[p] = values[static_cast<std::size_t>((*order)[p])];
  return copy.data();
}

}  // namespace

template <int D>
SnapshotWriter<D>::SnapshotWriter(fs::path directory, std::string stem, OutputMetadata meta, const Comm& comm)
    : directory_(std::move(directory)), stem_(std::move(stem)), meta_(std::move(meta)), comm_(comm) {
  if (stem_.empty()) throw std::invalid_argument("snapshot file stem must not be empty");
}

template <int D>
void SnapshotWriter<D>::set_next_index(int index) {
  if (index < 0) throw std::invalid_argument("snapshot index must be >= 0");
  next_index_ = index;
}

template <int D>
void SnapshotWriter<D>::set_entries(std::vector<Entry> entries) {
  entries_ = std::move(entries);
  info_.clear();
}

template <int D>
fs::path SnapshotWriter<D>::snapshot_path(int index) const {
  return directory_ / "snapshots" / fmt::format("{}-{:06d}.h5", stem_, index);
}

template <int D>
fs::path SnapshotWriter<D>::particles_xdmf_path() const {
  return directory_ / (stem_ + ".xdmf");
}

template <int D>
fs::path SnapshotWriter<D>::grid_xdmf_path() const {
  return directory_ / (stem_ == "particles" ? std::string("grid.xdmf") : stem_ + "-grid.xdmf");
}

template <int D>
void SnapshotWriter<D>::write(const Particles<D>& particles, double time, long long step,
                              const Grid<D>* grid, const NodeField<D>* nodes,
                              const std::vector<Vec3>* contact_normals,
                              const std::vector<std::int32_t>* order) {
  const std::size_t n = particles.n();
  if (order && order->size() != n) throw std::invalid_argument("snapshot: the particle order has the wrong length");
  const bool with_grid = grid != nullptr && nodes != nullptr;
  if (particles.reference_position.size() != n || particles.velocity.size() != n ||
      particles.mass.size() != n || particles.volume0.size() != n ||
      particles.deformation_gradient.size() != n || particles.kirchhoff_stress.size() != n ||
      particles.material.size() != n || particles.body.size() != n) {
    throw std::invalid_argument("snapshot: particle arrays have inconsistent lengths");
  }
  if (with_grid) {
    const auto nn = static_cast<std::size_t>(grid->n_nodes());
    if (nodes->mass.size() != nn || nodes->velocity_new.size() != nn) {
      throw std::invalid_argument(fmt::format(
          "snapshot: node field has {} nodes but the grid has {}", nodes->mass.size(), nn));
    }
  }

  // Derived particle quantities.
  std::vector<double> position(3 * n, 0.0), velocity(3 * n, 0.0), displacement(3 * n, 0.0);
  std::vector<double> volume(n), stress(6 * n), deformation(9 * n), pressure(n), von_mises(n);
  std::vector<std::int32_t> connectivity(n);
  // Row p of the file holds the particle stored at q = (*order)[p].
  const auto stored = [order](std::size_t p) { return order ? static_cast<std::size_t>((*order)[p]) : p; };
  for (std::size_t p = 0; p < n; ++p) {
    const std::size_t q = stored(p);
    connectivity[p] = static_cast<std::int32_t>(p);
    for (int a = 0; a < D; ++a) {
      position[3 * p + a] = particles.position[q][a];
      velocity[3 * p + a] = particles.velocity[q][a];
      displacement[3 * p + a] = particles.position[q][a] - particles.reference_position[q][a];
    }
    const Mat3& F = particles.deformation_gradient[q];
    const double J = F.determinant();
    volume[p] = J * particles.volume0[q];
    const Mat3 sigma = particles.kirchhoff_stress[q].full() / J;
    const double sxx = sigma(0, 0), syy = sigma(1, 1), szz = sigma(2, 2);
    const double syz = 0.5 * (sigma(1, 2) + sigma(2, 1));
    const double sxz = 0.5 * (sigma(0, 2) + sigma(2, 0));
    const double sxy = 0.5 * (sigma(0, 1) + sigma(1, 0));
    // VTK's order of a symmetric tensor, so that ParaView's labels XX YY ZZ XY YZ XZ are right.
    const double voigt[6] = {sxx, syy, szz, sxy, syz, sxz};
    for (int k = 0; k < 6; ++k) stress[6 * p + k] = voigt[k];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) deformation[9 * p + 3 * i + j] = F(i, j);
    pressure[p] = -(sxx + syy + szz) / 3.0;
    von_mises[p] = std::sqrt(0.5 * ((sxx - syy) * (sxx - syy) + (syy - szz) * (syy - szz) +
                                    (szz - sxx) * (szz - sxx)) +
                             3.0 * (syz * syz + sxz * sxz + sxy * sxy));
  }

  // Particles rank after rank (one rank: all of them, in order).
  const h5::Rows rows = h5::rows_of(comm_, n);
  for (std::size_t p = 0; p < n; ++p) connectivity[p] = static_cast<std::int32_t>(rows.first + p);

  // Grid node data over the domain nodes j = 0..n_cells per axis (no ghost layers; a periodic
  // axis repeats its first node at the end), x fastest, shape slowest axis first. Each rank
  // writes the box of those nodes it owns (all of them on one rank).
  FileInfo file_info;
  file_info.readable = true;
  file_info.current = true;
  file_info.n_particles = rows.total;
  for (const auto& v : meta_.state_variables) file_info.state_variables.push_back(v.name);
  std::vector<double> node_mass, node_velocity, node_normal;
  std::vector<std::size_t> box_start, box_count, vbox_start, vbox_count;
  if (with_grid) {
    file_info.has_grid = true;
    file_info.origin.assign(3, 0.0);
    file_info.spacing.assign(3, 1.0);

    for (int a = 0; a < D; ++a) {
      file_info.origin[a] = grid->origin()[a];
      file_info.spacing[a] = grid->cell_size()[a];
    }
    IVec<D> lo, hi;  // owned domain nodes [lo, hi): those whose cell (clamped) this rank owns
    for (int a = 0; a < D; ++a) {
      lo[a] = grid->own_lo()[a];
      hi[a] = grid->own_hi()[a] == grid->n_cells()[a] ? grid->n_cells()[a] + 1 : grid->own_hi()[a];
    }
    for (int a = D - 1; a >= 0; --a) {
      file_info.node_shape.push_back(static_cast<std::size_t>(grid->n_cells()[a] + 1));
      box_start.push_back(static_cast<std::size_t>(lo[a]));
      box_count.push_back(static_cast<std::size_t>(hi[a] - lo[a]));
    }
    vbox_start = box_start;
    vbox_start.push_back(0);
    vbox_count = box_count;
    vbox_count.push_back(3);
    const bool normals = contact_normals && contact_normals->size() == static_cast<std::size_t>(grid->n_nodes());
    file_info.has_contact_normal = comm_.any(normals);
    // The owned box in file order (x fastest).
    std::size_t box_nodes = 1;
    for (int a = 0; a < D; ++a) box_nodes *= static_cast<std::size_t>(hi[a] - lo[a]);
    node_mass.assign(box_nodes, 0.0);
    node_velocity.assign(3 * box_nodes, 0.0);
    if (file_info.has_contact_normal) node_normal.assign(3 * box_nodes, 0.0);
    IVec<D> j = lo;
    for (std::size_t k = 0; k < box_nodes; ++k) {
      const auto i = static_cast<std::size_t>(grid->node_index(j));
      node_mass[k] = nodes->mass[i];
      for (int a = 0; a < D; ++a) node_velocity[3 * k + a] = nodes->velocity_new[i][a];
      if (normals)
        for (int a = 0; a < 3; ++a) node_normal[3 * k + a] = (*contact_normals)[i][a];
      for (int a = 0; a < D; ++a) {
        if (++j[a] < hi[a]) break;
        j[a] = lo[a];
      }
    }
  }

  const fs::path target = snapshot_path(next_index_);
  const int z = meta_.compression;  // several ranks: written collectively (h5::write_doubles_rows)
  const std::string length = meta_.unit(Quantity::length), vel = meta_.unit(Quantity::velocity);
  const std::string stress_unit = meta_.unit(Quantity::stress), mass_unit = meta_.unit(Quantity::mass);
  write_file_atomically(target, comm_, [&](const fs::path& tmp) {
    h5::Handle file = h5::create_file(tmp, comm_);
    const hid_t root = file.get();
    h5::write_string_attribute(root, "format", "cairn-snapshot");
    h5::write_int64_attribute(root, "format_version", snapshot_format_version);
    h5::write_double_attribute(root, "time", time);
    h5::write_string_attribute(root, "time_units", meta_.unit(Quantity::time));
    h5::write_int64_attribute(root, "step", step);
    h5::write_int64_attribute(root, "dimension", D);
    h5::write_metadata(root, meta_, true);
    {
      h5::Handle g = h5::create_group(root, "particles");
      const hid_t gid = g.get();
      h5::write_doubles_rows(gid, "position", position.data(), rows, 3, z);
      h5::describe_dataset(gid, "position", length, "current position x (zero beyond D)", "x y z");
      h5::write_doubles_rows(gid, "velocity", velocity.data(), rows, 3, z);
      h5::describe_dataset(gid, "velocity", vel, "velocity v", "x y z");
      h5::write_doubles_rows(gid, "displacement", displacement.data(), rows, 3, z);
      h5::describe_dataset(gid, "displacement", length, "x - X (current minus reference position)", "x y z");
      std::vector<double> doubles;  // arranged() copies, one array at a time
      std::vector<std::int32_t> ints;
      h5::write_doubles_rows(gid, "mass", arranged(particles.mass, order, doubles), rows, 0, z);
      h5::describe_dataset(gid, "mass", mass_unit, "particle mass (per unit thickness times the thickness in 2D)");
      h5::write_doubles_rows(gid, "volume", volume.data(), rows, 0, z);
      h5::describe_dataset(gid, "volume", meta_.unit(Quantity::volume), "current volume det(F) V0");
      h5::write_doubles_rows(gid, "stress", stress.data(), rows, 6, z);
      h5::describe_dataset(gid, "stress", stress_unit,
                           "Cauchy stress sigma = tau / det(F), symmetric, VTK order", "xx yy zz xy yz xz");
      h5::write_doubles_rows(gid, "deformation_gradient", deformation.data(), rows, 9, z);
      h5::describe_dataset(gid, "deformation_gradient", "1", "F = dx/dX, row-major: F_iJ at 3 i + J",
                           "xx xy xz yx yy yz zx zy zz");
      for (int i = 0; i < 3; ++i) {
        const std::string row = std::string("deformation_gradient_") + "xyz"[i];
        h5::write_column_view(gid, row, "/particles/deformation_gradient", rows.total, 9,
                              3 * static_cast<std::size_t>(i), 3);
        h5::describe_dataset(gid, row, "1", fmt::format("row {} of F (a view of deformation_gradient)", "xyz"[i]),
                             fmt::format("{0}x {0}y {0}z", "xyz"[i]));
      }
      h5::write_doubles_rows(gid, "pressure", pressure.data(), rows, 0, z);
      h5::describe_dataset(gid, "pressure", stress_unit, "-trace(sigma)/3");
      h5::write_doubles_rows(gid, "von_mises", von_mises.data(), rows, 0, z);
      h5::describe_dataset(gid, "von_mises", stress_unit, "von Mises equivalent stress of sigma");
      std::vector<double> zero;  // runs without a thermal model store no temperatures
      if (particles.temperature.size() != n) zero.assign(n, 0.0);
      h5::write_doubles_rows(gid, "temperature", zero.empty() ? arranged(particles.temperature, order, doubles) : zero.data(),
                             rows, 0, z);
      h5::describe_dataset(gid, "temperature", meta_.unit(Quantity::temperature), "temperature");
      // The materials' state variables by name (Material::state_variables), NaN for particles
      // whose material has no such variable; the group attribute lists them for the XDMF.
      const auto width = static_cast<std::size_t>(particles.n_state_per_particle);
      std::string listed;
      for (const auto& v : meta_.state_variables) {
        doubles.resize(n);
        for (std::size_t p = 0; p < n; ++p) {
          const std::size_t q = stored(p);
          const auto m = static_cast<std::size_t>(particles.material[q]);
          const int k = m < v.index.size() ? v.index[m] : -1;
          doubles[p] = k >= 0 && static_cast<std::size_t>(k) < width ? particles.state[q * width + static_cast<std::size_t>(k)]
                                                                     : std::numeric_limits<double>::quiet_NaN();
        }
        h5::write_doubles_rows(gid, v.name, doubles.data(), rows, 0, z);
        h5::describe_dataset(gid, v.name, v.unit, v.description);
        if (!listed.empty()) listed += ' ';
        listed += v.name;
      }
      if (!listed.empty()) h5::write_string_attribute(gid, "state_variables", listed);
      h5::write_ints_rows(gid, "material", arranged(particles.material, order, ints), rows, z);
      h5::describe_dataset(gid, "material", "1", "index into /material_names");
      h5::write_ints_rows(gid, "body", arranged(particles.body, order, ints), rows, z);
      h5::describe_dataset(gid, "body", "1", "index into /body_names");
      if (particles.id.size() == n) {
        std::vector<std::int64_t> ids;
        h5::write_int64s_rows(gid, "id", arranged(particles.id, order, ids), rows, z);
        h5::describe_dataset(gid, "id", "1", "the particle's number (creation order), on any number of MPI ranks");
      }
      h5::write_ints_rows(gid, "connectivity", connectivity.data(), rows, z);
      h5::describe_dataset(gid, "connectivity", "1", "0..n-1: one vertex cell per particle (XDMF Polyvertex)");
    }
    if (with_grid) {
      h5::Handle g = h5::create_group(root, "grid");
      const hid_t gid = g.get();
      h5::write_doubles_box(gid, "node_mass", node_mass.data(), file_info.node_shape, box_start, box_count, z);
      h5::describe_dataset(gid, "node_mass", mass_unit, "lumped node mass");
      std::vector<std::size_t> vshape = file_info.node_shape;
      vshape.push_back(3);
      h5::write_doubles_box(gid, "node_velocity", node_velocity.data(), vshape, vbox_start, vbox_count, z);
      h5::describe_dataset(gid, "node_velocity", vel, "node velocity after the grid update", "x y z");
      if (file_info.has_contact_normal) {
        h5::write_doubles_box(gid, "contact_normal", node_normal.data(), vshape, vbox_start, vbox_count, z);
        h5::describe_dataset(gid, "contact_normal", "1", "unit contact normal (zero away from contact)", "x y z");
      }
      h5::write_doubles_attribute(gid, "origin", file_info.origin);
      h5::write_doubles_attribute(gid, "spacing", file_info.spacing);
      h5::write_string_attribute(gid, "units", length);
    }
  });

  const std::string name = target.filename().string();
  info_[name] = file_info;
  bool replaced = false;
  for (auto& entry : entries_) {
    if (entry.second == name) {
      entry.first = time;
      replaced = true;
    }
  }
  if (!replaced) entries_.emplace_back(time, name);
  ++next_index_;
  if (comm_.is_root()) write_xdmf();
}

template <int D>
const typename SnapshotWriter<D>::FileInfo& SnapshotWriter<D>::info(const std::string& file) {
  auto it = info_.find(file);
  if (it != info_.end()) return it->second;
  FileInfo fi;
  const fs::path path = directory_ / "snapshots" / file;
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) {
    try {
      h5::Handle f = h5::open_file(path);
      h5::Handle g = h5::open_group(f.get(), "particles");
      const std::vector<std::size_t> shape = h5::dataset_shape(g.get(), "mass");
      if (h5::has_attribute(g.get(), "state_variables")) {
        std::istringstream names(h5::read_string_attribute(g.get(), "state_variables"));
        for (std::string name; names >> name;) fi.state_variables.push_back(name);
      }
      if (shape.size() == 1) {
        fi.n_particles = shape[0];
        fi.readable = true;
      }
      fi.current = h5::has_attribute(f.get(), "format_version") &&
                   h5::read_int64_attribute(f.get(), "format_version") == snapshot_format_version;
      if (h5::has_child(f.get(), "grid")) {
        h5::Handle grid = h5::open_group(f.get(), "grid");
        fi.node_shape = h5::dataset_shape(grid.get(), "node_mass");
        fi.origin = h5::read_doubles_attribute(grid.get(), "origin");
        fi.spacing = h5::read_doubles_attribute(grid.get(), "spacing");
        fi.has_grid = fi.origin.size() == 3 && fi.spacing.size() == 3 && !fi.node_shape.empty() &&
                      fi.node_shape.size() <= 3;
        fi.has_contact_normal = h5::has_child(grid.get(), "contact_normal");
      }
    } catch (const std::runtime_error&) {
      fi = FileInfo{};  // unreadable: left out of the XDMF listing
    }
  }
  return info_[file] = fi;
}

template <int D>
void SnapshotWriter<D>::write_xdmf() {
  fmt::memory_buffer parts, grids;
  bool any_grid = false;
  parts.append(std::string_view(xdmf_header()));
  parts.append(std::string_view(
      "    <!-- stress: Cauchy stress, components XX YY ZZ XY YZ XZ; deformation_gradient_x/y/z: "
      "rows of F = dx/dX, components X Y Z (docs/output.md) -->\n"));
  fmt::format_to(std::back_inserter(parts),
                 "    <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
                 xml_escape(stem_));
  grids.append(std::string_view(xdmf_header()));
  grids.append(std::string_view(
      "    <Grid Name=\"grid\" GridType=\"Collection\" CollectionType=\"Temporal\">\n"));

  for (const auto& [time, file] : entries_) {
    const FileInfo& fi = info(file);
    if (!fi.readable) continue;
    const std::string n = std::to_string(fi.n_particles);
    const std::string grid_name = xml_escape(fs::path(file).stem().string());
    fmt::format_to(std::back_inserter(parts),
                   "      <Grid Name=\"{}\" GridType=\"Uniform\">\n"
                   "        <Time Value=\"{:.17g}\"/>\n"
                   "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" "
                   "NodesPerElement=\"1\">\n",
                   grid_name, time, n);
    // The connectivity makes every XDMF reader build one vertex cell per particle (without it
    // ParaView's Xdmf3 readers give points but no cells, and nothing is drawn).
    if (fi.current) hdf_item(parts, "          ", n, true, file, "/particles/connectivity");
    parts.append(std::string_view("        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n"));
    hdf_item(parts, "          ", n + " 3", false, file, "/particles/position");
    parts.append(std::string_view("        </Geometry>\n"));
    attribute(parts, "velocity", "Vector", n + " 3", false, file, "/particles/velocity");
    attribute(parts, "displacement", "Vector", n + " 3", false, file, "/particles/displacement");
    attribute(parts, "mass", "Scalar", n, false, file, "/particles/mass");
    attribute(parts, "volume", "Scalar", n, false, file, "/particles/volume");
    attribute(parts, "stress", fi.current ? "Tensor6" : "Matrix", n + " 6", false, file, "/particles/stress");
    if (fi.current) {
      for (const char* row : {"x", "y", "z"})
        attribute(parts, std::string("deformation_gradient_") + row, "Vector", n + " 3", false, file,
                  std::string("/particles/deformation_gradient_") + row);
    } else {
      attribute(parts, "deformation_gradient", "Tensor", n + " 9", false, file, "/particles/deformation_gradient");
    }
    attribute(parts, "pressure", "Scalar", n, false, file, "/particles/pressure");
    attribute(parts, "von_mises", "Scalar", n, false, file, "/particles/von_mises");
    attribute(parts, "temperature", "Scalar", n, false, file, "/particles/temperature");
    for (const auto& name : fi.state_variables)
      attribute(parts, name, "Scalar", n, false, file, "/particles/" + name);
    attribute(parts, "material", "Scalar", n, true, file, "/particles/material");
    attribute(parts, "body", "Scalar", n, true, file, "/particles/body");
    parts.append(std::string_view("      </Grid>\n"));

    if (!fi.has_grid) continue;
    any_grid = true;
    // Always a 3D mesh (a 2D grid is one node thick in z, a 1D grid in y and z), so that it lies
    // in the particles' x-y plane in every reader; Dimensions, origin and spacing are listed
    // slowest axis first (z y x). The node arrays keep their D-dimensional shape.
    std::vector<std::size_t> dims3 = fi.node_shape;
    while (dims3.size() < 3) dims3.insert(dims3.begin(), 1);
    const std::string dims = join(dims3);
    const std::string origin = fmt::format("{:.17g} {:.17g} {:.17g}", fi.origin[2], fi.origin[1], fi.origin[0]);
    const std::string spacing = fmt::format("{:.17g} {:.17g} {:.17g}", fi.spacing[2], fi.spacing[1], fi.spacing[0]);
    fmt::format_to(std::back_inserter(grids),
                   "      <Grid Name=\"{}\" GridType=\"Uniform\">\n"
                   "        <Time Value=\"{:.17g}\"/>\n"
                   "        <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{}\"/>\n"
                   "        <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
                   "          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
                   "Format=\"XML\">{}</DataItem>\n"
                   "          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
                   "Format=\"XML\">{}</DataItem>\n"
                   "        </Geometry>\n",
                   grid_name, time, dims, origin, spacing);
    attribute(grids, "node_mass", "Scalar", dims, false, file, "/grid/node_mass");
    attribute(grids, "node_velocity", "Vector", dims + " 3", false, file, "/grid/node_velocity");
    if (fi.has_contact_normal)
      attribute(grids, "contact_normal", "Vector", dims + " 3", false, file, "/grid/contact_normal");
    grids.append(std::string_view("      </Grid>\n"));
  }
  const std::string_view footer("    </Grid>\n  </Domain>\n</Xdmf>\n");
  parts.append(footer);
  grids.append(footer);
  write_text_atomically(particles_xdmf_path(), fmt::to_string(parts));
  std::error_code ec;
  if (any_grid) {
    write_text_atomically(grid_xdmf_path(), fmt::to_string(grids));
  } else if (fs::exists(grid_xdmf_path(), ec)) {
    fs::remove(grid_xdmf_path(), ec);  // no listed snapshot has grid data (any more)
  }
}

template <int D>
void SnapshotWriter<D>::restore(std::vector<Entry> entries, int next_index) {
  set_entries(std::move(entries));
  set_next_index(next_index);
  // Files of this series numbered next_index or later belong to the abandoned continuation of
  // the run: remove them, so that the folder, the XDMF files and history.csv all end at the
  // restored time. On several ranks rank 0 alone touches the files.
  if (!comm_.is_root()) {
    comm_.barrier();
    return;
  }
  std::error_code ec;
  const fs::path folder = directory_ / "snapshots";
  if (fs::is_directory(folder, ec)) {
    const std::string prefix = stem_ + "-";
    std::vector<fs::path> stale;
    for (const auto& e : fs::directory_iterator(folder, ec)) {
      const std::string name = e.path().filename().string();
      if (name.size() != prefix.size() + 9 || name.compare(0, prefix.size(), prefix) != 0 ||
          e.path().extension() != ".h5")
        continue;
      const std::string digits = name.substr(prefix.size(), 6);
      if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
      if (std::stoi(digits) >= next_index) stale.push_back(e.path());
    }
    for (const auto& p : stale) fs::remove(p, ec);
  }
  write_xdmf();
  comm_.barrier();
}

template class SnapshotWriter<1>;
template class SnapshotWriter<2>;
template class SnapshotWriter<3>;

}  // namespace cairn
