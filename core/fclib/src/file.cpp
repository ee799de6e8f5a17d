// fclib files through Debian's libfclib, each dataset checked with HDF5 before libfclib reads it
// (libfclib allocates from one dataset's value and reads another into it, and exits the process on a
// failed read), then every size, index and value checked again on the problem read (fclib.hpp).
#include "impetus/fclib/fclib.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"

extern "C" {  // fclib.h declares C functions without saying so
#include <fclib.h>
}
#include <hdf5.h>
#include <hdf5_hl.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

namespace impetus::fclib {

namespace {

// Matrices and vectors larger than this (entries) are refused before anything is allocated: 64 Mi
// entries (512 MiB of doubles), far above fclib's published problems (≈ 10⁶ non-zeros), and a bound on
// what a small compressed file can make the reader allocate.
constexpr long long kMaxEntries = 1ll << 26;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw Error(file.string() + ": " + what);
}

// An open HDF5 file, closed on scope exit; HDF5's own error printing is off while it lives.
class Hdf5File {
 public:
  explicit Hdf5File(const std::filesystem::path& file) : file_(file) {
    H5Eget_auto2(H5E_DEFAULT, &old_handler_, &old_data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    if (H5Fis_hdf5(file.c_str()) <= 0) {
      restore();
      fail(file, "not an HDF5 file (an fclib problem is an HDF5 file)");
    }
    id_ = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (id_ < 0) {
      restore();
      fail(file, "HDF5 cannot open it");
    }
  }
  ~Hdf5File() {
    if (id_ >= 0) H5Fclose(id_);
    restore();
  }
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;

  // Whether every link along `path` ("/a/b/c") exists.
  bool exists(const std::string& path) const {
    for (std::size_t at = path.find('/', 1);; at = path.find('/', at + 1)) {
      const std::string prefix = path.substr(0, at);
      if (H5Lexists(id_, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      if (at == std::string::npos) return true;
    }
  }

  // The number of elements of the rank-1 numeric dataset `path` (refused otherwise).
  long long elements(const std::string& path, bool integer) const {
    if (!exists(path)) fail(file_, "dataset " + path + " is missing");
    int rank = 0;
    if (H5LTget_dataset_ndims(id_, path.c_str(), &rank) < 0) fail(file_, path + " is not a dataset");
    if (rank != 1) fail(file_, path + " has rank " + std::to_string(rank) + " (fclib stores vectors)");
    hsize_t dim = 0;
    H5T_class_t type{};
    std::size_t size = 0;
    if (H5LTget_dataset_info(id_, path.c_str(), &dim, &type, &size) < 0) fail(file_, path + " cannot be read");
    if (const bool numeric = integer ? type == H5T_INTEGER : (type == H5T_FLOAT || type == H5T_INTEGER); !numeric)
      fail(file_, path + " is not " + (integer ? "an integer" : "a number") + " dataset");
    return static_cast<long long>(dim);
  }
  // Checks that `path` has `count` entries and can be read whole (libfclib exits the process on a read
  // that fails, e.g. in a truncated file, so every dataset it reads is read here first).
  void expect(const std::string& path, long long count, bool integer) const {
    if (const long long n = elements(path, integer); n != count)
      fail(file_, path + " has " + std::to_string(n) + " entries where fclib expects " + std::to_string(count));
    if (count > kMaxEntries) fail(file_, path + " has " + std::to_string(count) + " entries (more than Impetus reads)");
    const bool read = integer ? H5LTread_dataset_int(id_, path.c_str(), std::vector<int>(static_cast<std::size_t>(count)).data()) >= 0
                              : H5LTread_dataset_double(id_, path.c_str(), std::vector<double>(static_cast<std::size_t>(count)).data()) >= 0;
    if (!read) fail(file_, path + " cannot be read (the file is damaged or truncated)");
  }
  int scalar(const std::string& path) const {
    expect(path, 1, true);
    int value = 0;
    if (H5LTread_dataset_int(id_, path.c_str(), &value) < 0) fail(file_, path + " cannot be read");
    return value;
  }
  void string_if_present(const std::string& path) const {
    if (!exists(path)) return;
    H5T_class_t type{};
    hsize_t dim = 0;
    std::size_t size = 0;
    int rank = -1;
    if (H5LTget_dataset_ndims(id_, path.c_str(), &rank) < 0 || rank != 0 ||
        H5LTget_dataset_info(id_, path.c_str(), &dim, &type, &size) < 0 || type != H5T_STRING)
      fail(file_, path + " is not a string");
    // fclib reads it into `size` bytes, which holds a fixed-length string only.
    const hid_t dataset = H5Dopen2(id_, path.c_str(), H5P_DEFAULT);
    const hid_t string_type = dataset >= 0 ? H5Dget_type(dataset) : -1;
    const bool fixed = string_type >= 0 && H5Tis_variable_str(string_type) == 0;
    if (string_type >= 0) H5Tclose(string_type);
    if (dataset >= 0) H5Dclose(dataset);
    if (!fixed) fail(file_, path + " is not a fixed-length string");
  }

  // Checks the datasets fclib's read_matrix reads in group `path`; returns {rows, columns}.
  std::pair<int, int> matrix(const std::string& path) const {
    const int nzmax = scalar(path + "/nzmax"), m = scalar(path + "/m"), n = scalar(path + "/n"),
              nz = scalar(path + "/nz");
    if (nzmax < 0 || m < 0 || n < 0 || nzmax > kMaxEntries || m > kMaxEntries || n > kMaxEntries)
      fail(file_, path + ": sizes nzmax " + std::to_string(nzmax) + ", m " + std::to_string(m) + ", n " +
                      std::to_string(n) + " out of range");
    if (nz >= 0) {  // triplets
      if (nz > nzmax) fail(file_, path + ": " + std::to_string(nz) + " triplets but nzmax " + std::to_string(nzmax));
      expect(path + "/p", nz, true);
      expect(path + "/i", nz, true);
    } else if (nz == -1 || nz == -2) {  // compressed columns, rows
      expect(path + "/p", (nz == -1 ? n : m) + 1ll, true);
      expect(path + "/i", nzmax, true);
    } else {
      fail(file_, path + "/nz is " + std::to_string(nz) + " (fclib knows ≥ 0 triplets, −1 columns, −2 rows)");
    }
    expect(path + "/x", nzmax, false);
    if (exists(path + "/conditioning")) {
      string_if_present(path + "/comment");
      expect(path + "/conditioning", 1, false);
      expect(path + "/determinant", 1, false);
      expect(path + "/rank", 1, true);
    }
    return {m, n};
  }

  void info(const std::string& path) const {
    for (const char* name : {"/title", "/description", "/math_info"}) string_if_present(path + name);
  }

 private:
  void restore() { H5Eset_auto2(H5E_DEFAULT, old_handler_, old_data_); }

  std::filesystem::path file_;
  hid_t id_ = -1;
  H5E_auto2_t old_handler_ = nullptr;
  void* old_data_ = nullptr;
};

// Checks everything fclib_read_local / fclib_read_global will read. Returns the form stored.
Form check_layout(const std::filesystem::path& file) {
  const Hdf5File h5(file);
  const bool local = h5.exists("/fclib_local"), global = h5.exists("/fclib_global");
  if (!local && !global) fail(file, "no fclib problem in it (neither /fclib_local nor /fclib_global)");
  const std::string root = local ? "/fclib_local" : "/fclib_global";
  if (const int d = h5.scalar(root + "/spacedim"); d != 3)
    fail(file, root + "/spacedim is " + std::to_string(d) + " (Impetus solves 3-D contact problems only)");
  if (local) {
    const auto [m, n] = h5.matrix(root + "/W");
    if (m != n || m % 3 != 0)
      fail(file, "W is " + std::to_string(m) + " × " + std::to_string(n) + " (square, 3 rows per contact)");
    long long p = 0;
    if (h5.exists(root + "/V")) {
      const auto [vm, vn] = h5.matrix(root + "/V");
      if (!h5.exists(root + "/R")) fail(file, root + "/V is given without R");
      const auto [rm, rn] = h5.matrix(root + "/R");
      if (vm != m || rm != vn || rn != vn)
        fail(file, "V (" + std::to_string(vm) + " × " + std::to_string(vn) + ") and R (" + std::to_string(rm) +
                       " × " + std::to_string(rn) + ") disagree with W's " + std::to_string(m) + " rows");
      p = vn;
    } else if (h5.exists(root + "/R")) {
      fail(file, root + "/R is given without V");
    }
    h5.expect(root + "/vectors/q", m, false);
    h5.expect(root + "/vectors/mu", m / 3, false);
    if (p > 0) h5.expect(root + "/vectors/s", p, false);
  } else {
    const auto [mm, mn] = h5.matrix(root + "/M");
    const auto [hm, hn] = h5.matrix(root + "/H");
    if (mm != mn || hm != mm || hn % 3 != 0)
      fail(file, "M is " + std::to_string(mm) + " × " + std::to_string(mn) + " and H " + std::to_string(hm) + " × " +
                     std::to_string(hn) + " (M square, H with M's rows and 3 columns per contact)");
    h5.expect(root + "/vectors/f", mm, false);
    h5.expect(root + "/vectors/w", hn, false);
    h5.expect(root + "/vectors/mu", hn / 3, false);
    if (h5.exists(root + "/G")) {
      const auto [gm, gn] = h5.matrix(root + "/G");
      if (gm != mm) fail(file, "G has " + std::to_string(gm) + " rows, M " + std::to_string(mm));
      h5.expect(root + "/vectors/b", gn, false);
    }
  }
  if (h5.exists(root + "/info")) h5.info(root + "/info");
  return local ? Form::local : Form::global;
}

// An fclib matrix (triplets, columns or rows; sizes checked by check_layout) as compressed columns,
// every index checked.
SparseMatrix to_eigen(const std::filesystem::path& file, const std::string& name, const fclib_matrix& a) {
  std::vector<Eigen::Triplet<double>> entries;
  auto add = [&](long long row, long long column, double value) {
    if (row < 0 || row >= a.m || column < 0 || column >= a.n)
      fail(file, name + " has an entry at (" + std::to_string(row) + ", " + std::to_string(column) +
                     ") outside its " + std::to_string(a.m) + " × " + std::to_string(a.n));
    if (!std::isfinite(value)) fail(file, name + " has a non-finite entry at (" + std::to_string(row) + ", " + std::to_string(column) + ")");
    entries.emplace_back(static_cast<int>(row), static_cast<int>(column), value);
  };
  if (a.nz >= 0) {
    for (int k = 0; k < a.nz; ++k) add(a.p[k], a.i[k], a.x[k]);
  } else {
    const int outer = a.nz == -1 ? a.n : a.m;
    if (a.p[0] != 0 || a.p[outer] > a.nzmax) fail(file, name + "'s pointers do not span [0, nzmax]");
    for (int j = 0; j < outer; ++j) {
      if (a.p[j + 1] < a.p[j]) fail(file, name + "'s pointers decrease at " + std::to_string(j));
      for (int k = a.p[j]; k < a.p[j + 1]; ++k)
        a.nz == -1 ? add(a.i[k], j, a.x[k]) : add(j, a.i[k], a.x[k]);
    }
  }
  SparseMatrix out(a.m, a.n);
  out.setFromTriplets(entries.begin(), entries.end());  // duplicates are summed, as fclib's triplets mean
  return out;
}

Vector to_vector(const std::filesystem::path& file, const std::string& name, const double* data, long long size) {
  Vector out(size);
  for (long long k = 0; k < size; ++k) {
    if (!std::isfinite(data[k])) fail(file, name + "[" + std::to_string(k) + "] is not finite");
    out(k) = data[k];
  }
  return out;
}

std::vector<double> friction(const std::filesystem::path& file, const double* data, long long contacts) {
  std::vector<double> mu(data, data + contacts);
  for (long long c = 0; c < contacts; ++c)
    if (!(mu[c] >= 0.0) || !std::isfinite(mu[c]))
      fail(file, "mu[" + std::to_string(c) + "] is " + format_number(mu[c]) + " (a friction coefficient is finite and ≥ 0)");
  return mu;
}

Info read_info(const fclib_info* info) {
  Info out;
  if (!info) return out;
  if (info->title) out.title = info->title;
  if (info->description) out.description = info->description;
  if (info->math_info) out.math_info = info->math_info;
  return out;
}

void check_symmetric(const std::filesystem::path& file, const std::string& name, const SparseMatrix& a) {
  if (a.nonZeros() == 0) return;
  const SparseMatrix difference = a - SparseMatrix(a.transpose());
  const double scale = a.coeffs().cwiseAbs().maxCoeff();
  const double asymmetry = difference.nonZeros() > 0 ? difference.coeffs().cwiseAbs().maxCoeff() : 0.0;
  if (asymmetry > 1e-9 * scale)
    fail(file, name + " is not symmetric (|" + name + " − " + name + "ᵀ| reaches " + format_number(asymmetry) +
                   " against entries up to " + format_number(scale) + ")");
}

// fclib's arrays of a compressed-column matrix (views into `a`, which must outlive them).
fclib_matrix view_of(const SparseMatrix& a) {
  fclib_matrix view{};
  view.nzmax = static_cast<int>(a.nonZeros());
  view.m = static_cast<int>(a.rows());
  view.n = static_cast<int>(a.cols());
  view.p = const_cast<int*>(a.outerIndexPtr());
  view.i = const_cast<int*>(a.innerIndexPtr());
  view.x = const_cast<double*>(a.valuePtr());
  view.nz = -1;
  return view;
}

// A local problem as libfclib's struct: the contact block W, the mixed blocks V, R and the vectors q, s
// split out of LocalProblem's [W V; Vᵀ R] and [q; s] (owned here; `local` points into them).
class LocalView {
 public:
  explicit LocalView(const LocalProblem& problem) {
    const auto c = static_cast<Eigen::Index>(3 * problem.contacts()), e = static_cast<Eigen::Index>(problem.equalities);
    SparseMatrix whole = problem.w;
    whole.makeCompressed();
    w_ = whole.topLeftCorner(c, c);
    v_ = whole.topRightCorner(c, e);
    r_ = whole.bottomRightCorner(e, e);
    for (SparseMatrix* a : {&w_, &v_, &r_}) a->makeCompressed();
    q_ = problem.q.head(c);
    s_ = problem.q.tail(e);
    w_view_ = view_of(w_);
    v_view_ = view_of(v_);
    r_view_ = view_of(r_);
    local.W = &w_view_;
    local.V = e > 0 ? &v_view_ : nullptr;
    local.R = e > 0 ? &r_view_ : nullptr;
    local.mu = const_cast<double*>(problem.mu.data());
    local.q = q_.data();
    local.s = e > 0 ? s_.data() : nullptr;
    local.spacedim = 3;
  }
  LocalView(const LocalView&) = delete;
  LocalView& operator=(const LocalView&) = delete;

  fclib_local local{};

 private:
  SparseMatrix w_, v_, r_;
  Vector q_, s_;
  fclib_matrix w_view_{}, v_view_{}, r_view_{};
};

struct InfoStrings {
  std::string title, description, math_info;
  fclib_info info{};
  explicit InfoStrings(const Info& in) : title(in.title), description(in.description), math_info(in.math_info) {
    // fclib writes a string only if its pointer is set, and cannot write an empty one.
    info.title = title.empty() ? nullptr : title.data();
    info.description = description.empty() ? nullptr : description.data();
    info.math_info = math_info.empty() ? nullptr : math_info.data();
  }
};

void written(const std::filesystem::path& file, int status) {
  if (!status) fail(file, "fclib could not write the problem");
}

void refuse_existing(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::exists(file, ec)) fail(file, "exists already (fclib would add to it); remove it first");
}

}  // namespace

FileProblem read_problem(const std::filesystem::path& file) {
  {
    std::ifstream probe(file, std::ios::binary);
    if (!probe) fail(file, "cannot be opened for reading");
  }
  FileProblem out;
  out.form = check_layout(file);
  if (out.form == Form::local) {
    const std::unique_ptr<fclib_local, void (*)(fclib_local*)> p(fclib_read_local(file.c_str()), [](fclib_local* x) {
      if (x) fclib_delete_local(x);
      std::free(x);
    });
    if (!p) fail(file, "fclib could not read its local problem");
    const SparseMatrix w = to_eigen(file, "W", *p->W);
    const long long m = p->W->m, equalities = p->R ? p->R->n : 0;
    LocalProblem& local = out.local;
    local.mu = friction(file, p->mu, m / 3);
    local.equalities = static_cast<std::size_t>(equalities);
    local.q.resize(m + equalities);
    local.q.head(m) = to_vector(file, "q", p->q, m);
    if (equalities > 0) {
      const SparseMatrix v = to_eigen(file, "V", *p->V), r = to_eigen(file, "R", *p->R);
      local.q.tail(equalities) = to_vector(file, "s", p->s, equalities);
      std::vector<Eigen::Triplet<double>> entries;
      auto add = [&](const SparseMatrix& a, long long row0, long long col0, bool transpose) {
        for (Eigen::Index j = 0; j < a.outerSize(); ++j)
          for (SparseMatrix::InnerIterator it(a, j); it; ++it)
            transpose ? entries.emplace_back(col0 + j, row0 + it.row(), it.value())
                      : entries.emplace_back(row0 + it.row(), col0 + j, it.value());
      };
      add(w, 0, 0, false);
      add(v, 0, m, false);
      add(v, 0, m, true);
      add(r, m, m, false);
      local.w.resize(m + equalities, m + equalities);
      local.w.setFromTriplets(entries.begin(), entries.end());
    } else {
      local.w = w;
    }
    check_symmetric(file, equalities > 0 ? "[W V; Vᵀ R]" : "W", local.w);
    local.info = read_info(p->info);
    return out;
  }
  const std::unique_ptr<fclib_global, void (*)(fclib_global*)> p(fclib_read_global(file.c_str()), [](fclib_global* x) {
    if (x) fclib_delete_global(x);
    std::free(x);
  });
  if (!p) fail(file, "fclib could not read its global problem");
  GlobalProblem& g = out.global;
  g.m = to_eigen(file, "M", *p->M);
  g.h = to_eigen(file, "H", *p->H);
  g.g = p->G ? to_eigen(file, "G", *p->G) : SparseMatrix(g.m.rows(), 0);
  g.f = to_vector(file, "f", p->f, g.m.rows());
  g.w = to_vector(file, "w", p->w, g.h.cols());
  g.b = p->G ? to_vector(file, "b", p->b, g.g.cols()) : Vector();
  g.mu = friction(file, p->mu, g.h.cols() / 3);
  g.info = read_info(p->info);
  check_symmetric(file, "M", g.m);
  try {
    out.local = reduce(g);
  } catch (const Error& e) {
    fail(file, e.what());
  }
  return out;
}

void write_problem(const std::filesystem::path& file, const LocalProblem& problem) {
  refuse_existing(file);
  LocalView view(problem);
  InfoStrings info(problem.info);
  view.local.info = &info.info;
  written(file, fclib_write_local(&view.local, file.c_str()));
}

void write_problem(const std::filesystem::path& file, const GlobalProblem& problem) {
  refuse_existing(file);
  SparseMatrix m = problem.m, h = problem.h, g = problem.g;
  m.makeCompressed();
  h.makeCompressed();
  g.makeCompressed();
  fclib_matrix mv = view_of(m), hv = view_of(h), gv = view_of(g);
  InfoStrings info(problem.info);
  Vector f = problem.f, w = problem.w, b = problem.b;
  fclib_global global{};
  global.M = &mv;
  global.H = &hv;
  global.G = g.cols() > 0 ? &gv : nullptr;
  global.mu = const_cast<double*>(problem.mu.data());
  global.f = f.data();
  global.w = w.data();
  global.b = g.cols() > 0 ? b.data() : nullptr;
  global.spacedim = 3;
  global.info = &info.info;
  written(file, fclib_write_global(&global, file.c_str()));
}

double merit(const LocalProblem& problem, const Vector& r) {
  LocalView view(problem);
  const auto c = static_cast<Eigen::Index>(3 * problem.contacts());
  Vector contact_r = r.head(c), lambda = r.tail(static_cast<Eigen::Index>(problem.equalities));
  Vector u = (problem.w * r + problem.q).head(c);
  fclib_solution solution{};
  solution.r = contact_r.data();
  solution.u = u.data();
  solution.l = problem.equalities > 0 ? lambda.data() : nullptr;
  return fclib_merit_local(&view.local, MERIT_1, &solution);
}

}  // namespace impetus::fclib
