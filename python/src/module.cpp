// tsi._tsi: the native half of the Python package (python/tsi/__init__.py is the other).
// Everything goes through the runner's library (apps/tsi: resolve_run_config, execute_run,
// expand_study, run_study, study_rows), so a config means in Python what it means to `tsi run`.
// Configs and results cross as JSON text; the package turns them into dicts and numpy arrays.
#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include "config.hpp"
#include "interrupt.hpp"
#include "list_command.hpp"
#include "plugin_setup.hpp"
#include "progress.hpp"
#include "run.hpp"
#include "run_files.hpp"
#include "study_command.hpp"
#include "study_report.hpp"
#include "study_runner.hpp"
#include "study_spec.hpp"
#include "tsi/context.hpp"
#include "tsi/error.hpp"
#include "tsi/matrix_model.hpp"
#include "tsi/model.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"
#include "tsi/version.hpp"

namespace py = pybind11;
using tsi::Json;

namespace {

// The Python session's registry and loader, shared with every plugin loaded from Python. Never
// destroyed: plugins and Python models registered into it live as long as the interpreter.
tsi::Registry& session_registry() {
  static auto* instance = new tsi::Registry;
  return *instance;
}

tsi::PluginLoader& loader() {
  static auto* instance = new tsi::PluginLoader(session_registry());
  return *instance;
}

Json parse(const std::string& text, const std::string& origin) {
  std::istringstream in(text);
  return tsi::app::parse_json(in, origin);
}

// Runs `work` on a worker thread while this (the Python main) thread waits with the GIL
// released, waking every 50 ms to let Python handle its signals: a Ctrl-C (KeyboardInterrupt)
// becomes the runner's interrupt request, and the run or study stops at its next step and
// returns what it has (status "interrupted"). Exceptions of `work` are rethrown here.
template <class Result, class Work>
Result interruptible(Work&& work, bool& was_interrupted, const std::function<void()>& while_waiting = {}) {
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
  Result result{};
  std::exception_ptr error;
  tsi::app::clear_interrupt();
  std::thread worker([&] {
    try {
      result = work();
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
    cv.notify_all();
  });
  was_interrupted = false;
  for (;;) {
    bool finished = false;
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      finished = cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; });
    }
    if (while_waiting) while_waiting();
    if (finished) break;
    if (PyErr_CheckSignals() != 0) {  // KeyboardInterrupt (or another handler's exception)
      PyErr_Clear();
      was_interrupted = true;
      tsi::app::request_interrupt(SIGINT);
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  tsi::app::clear_interrupt();
  if (error) std::rethrow_exception(error);
  return result;
}

// ---- Models written in Python -------------------------------------------------------------

std::string type_name(const py::handle& value) {
  return py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>();
}

// What a Python function returned, as a message names it: "a NoneType", "an array of shape
// (3, 64) and dtype float64".
std::string described(const py::handle& value) {
  if (py::isinstance<py::array>(value)) {
    const auto a = py::reinterpret_borrow<py::array>(value);
    std::string shape;
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
    if (a.ndim() == 1) shape += ",";
    return fmt::format("an array of shape ({}) and dtype {}", shape, py::str(a.dtype()).cast<std::string>());
  }
  return "a " + type_name(value);
}

// What `who` returned as Values (a complex matrix or vector, a double), or a tsi::Error naming
// what it returned and what was expected instead of pybind11's "Unable to cast".
template <class Values>
Values returned(const py::object& value, const std::string& who, const std::string& expected) {
  try {
    return value.cast<Values>();
  } catch (const py::cast_error&) {
    throw tsi::Error(fmt::format("{} returned {}, expected {}", who, described(value), expected));
  }
}

// Refuses complex values with an imaginary part that a function of a real model or field
// returned: the real states would drop it silently. A real array (the usual return) is not scanned.
template <class Values>
void check_real(const py::handle& value, const Values& values, const std::string& who, const char* remedy) {
  if (py::isinstance<py::array>(value)) {
    const char kind = py::reinterpret_borrow<py::array>(value).dtype().kind();
    if (kind == 'f' || kind == 'i' || kind == 'u' || kind == 'b') return;
  }
  if ((values.imag().array() == 0.0).all()) return;
  throw tsi::Error(fmt::format("{} returned complex values (imaginary parts up to {:.3g}) where the states are real, "
                               "which would drop them: {}",
                               who, values.imag().cwiseAbs().maxCoeff(), remedy));
}

// Python's truth values: bool and numpy.bool_ (not 1, "yes" or None).
bool is_bool(py::handle value) {
  return PyBool_Check(value.ptr()) || type_name(value) == "bool_";
}
bool is_integer(py::handle value) { return !is_bool(value) && PyIndex_Check(value.ptr()) != 0; }
bool is_real(py::handle value) {
  return !is_bool(value) && !PyComplex_Check(value.ptr()) && PyNumber_Check(value.ptr()) != 0;
}

// Calls into a Python model, with the GIL, turning a Python exception into a tsi::Error that
// names the model and the method (the run then fails with that message, as a C++ model's would).
template <class F>
auto call_python(const std::string& model, const char* method, F&& f) {
  py::gil_scoped_acquire gil;
  try {
    return f();
  } catch (py::error_already_set& e) {
    throw tsi::Error(fmt::format("python model \"{}\": {}: {}", model, method, e.what()));
  } catch (const py::cast_error& e) {
    throw tsi::Error(fmt::format("python model \"{}\": {} returned a value of the wrong type: {}", model, method,
                                 e.what()));
  }
}

class PythonModel final : public tsi::Model, public tsi::HamiltonianStructure, public tsi::FusedTauGrid {
 public:
  PythonModel(double eps, py::object instance, std::string name)
      : Model(eps), name_(std::move(name)), self_(instance.release().ptr()) {
    try {
      py::handle self(self_);
      dim_ = attribute<tsi::Index>("dim", "a positive integer", is_integer);
      if (dim_ <= 0) throw tsi::ConfigError("model.name", fmt::format("python model \"{}\": dim = {}, expected a positive integer", name_, dim_));
      complex_ = py::hasattr(self, "is_complex") && attribute<bool>("is_complex", "True or False", is_bool);
      has_filtered_ = py::hasattr(self, "filtered_field");
      has_derivative_ = py::hasattr(self, "nonlinear_field_derivative");
      // `hamiltonian = False`: the general class, with apply_A instead of apply_M, apply_J and H1.
      hamiltonian_ = !py::hasattr(self, "hamiltonian") || attribute<bool>("hamiltonian", "True or False", is_bool);
      has_apply_A_ = py::hasattr(self, "apply_A");
      if (py::hasattr(self, "max_linear_frequency")) {
        max_frequency_ = attribute<double>("max_linear_frequency", "a finite positive number", is_real);
        if (!(std::isfinite(max_frequency_) && max_frequency_ > 0))  // the fast period divides by it
          throw tsi::ConfigError("model.name", fmt::format("python model \"{}\": max_linear_frequency = {}, expected a "
                                                           "finite positive number", name_, max_frequency_));
      }
    } catch (...) {
      py::handle(self_).dec_ref();  // no destructor runs for a constructor that throws
      throw;
    }
  }
  ~PythonModel() override {
    if (Py_IsInitialized()) {
      py::gil_scoped_acquire gil;
      py::handle(self_).dec_ref();
    }
  }

  tsi::Index dim() const override { return dim_; }
  bool is_complex() const override { return complex_; }
  // `hamiltonian = False` declares no Hamiltonian structure; a class with filtered_field
  // declares the fused capability (its tau grid handed over as one numpy array), one without
  // gets tsi's flow, field and flow back.
  const tsi::HamiltonianStructure* hamiltonian() const override { return hamiltonian_ ? this : nullptr; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return has_filtered_ ? this : nullptr; }
  double max_linear_frequency() const override { return max_frequency_; }

  void linear_flow(const tsi::RealVector& taus, tsi::MatrixRef states) const override {
    call_python(name_, "linear_flow", [&] {
      store(states, self().attr("linear_flow")(taus, batch(states)), "linear_flow");
    });
  }

  void nonlinear_field(tsi::ConstMatrixRef states, tsi::MatrixRef out) const override {
    call_python(name_, "nonlinear_field", [&] {
      store(out, self().attr("nonlinear_field")(batch(states)), "nonlinear_field");
    });
  }

  void filtered_field(const tsi::RealVector& taus, tsi::MatrixRef states, tsi::MatrixRef out) const override {
    call_python(name_, "filtered_field", [&] {
      store(out, self().attr("filtered_field")(taus, batch(states)), "filtered_field");
    });
  }

  // The run's tau grid as a numpy array made once, handed to filtered_field at every call.
  class GridField final : public tsi::TauGridField {
   public:
    GridField(const PythonModel& model, const tsi::RealVector& taus) : model_(model), taus_(taus) {
      py::gil_scoped_acquire gil;
      array_ = py::cast(taus_).release().ptr();
    }
    ~GridField() override {
      if (Py_IsInitialized()) {
        py::gil_scoped_acquire gil;
        py::handle(array_).dec_ref();
      }
    }
    void evaluate(tsi::MatrixRef states, tsi::MatrixRef out) override {
      call_python(model_.name_, "filtered_field", [&] {
        model_.store(out, model_.self().attr("filtered_field")(py::handle(array_), model_.batch(states)),
                     "filtered_field");
      });
    }

   private:
    const PythonModel& model_;
    tsi::RealVector taus_;
    PyObject* array_;
  };

  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(*this, taus);
  }

  void nonlinear_field_derivative(tsi::ConstMatrixRef states, tsi::ConstMatrixRef directions,
                                  tsi::MatrixRef out) const override {
    if (!has_derivative_) return Model::nonlinear_field_derivative(states, directions, out);
    call_python(name_, "nonlinear_field_derivative", [&] {
      store(out, self().attr("nonlinear_field_derivative")(batch(states), batch(directions)),
            "nonlinear_field_derivative");
    });
  }

  void apply_A(const tsi::Vector& u, tsi::Vector& out) const override {
    if (!has_apply_A_) return Model::apply_A(u, out);
    out = call_python(name_, "apply_A", [&] { return vector(self().attr("apply_A")(one(u)), "apply_A"); });
  }
  void apply_M(const tsi::Vector& u, tsi::Vector& out) const override {
    out = call_python(name_, "apply_M", [&] { return vector(self().attr("apply_M")(one(u)), "apply_M"); });
  }
  void apply_J(const tsi::Vector& u, tsi::Vector& out) const override {
    out = call_python(name_, "apply_J", [&] { return vector(self().attr("apply_J")(one(u)), "apply_J"); });
  }
  double H1(const tsi::Vector& u) const override {
    return call_python(name_, "H1", [&] {
      return returned<double>(self().attr("H1")(one(u)), who("H1"), "a real number");
    });
  }
  tsi::Vector initial_value() const override {
    return call_python(name_, "initial_value",
                       [&] { return vector(self().attr("initial_value")(), "initial_value"); });
  }

 private:
  py::handle self() const { return py::handle(self_); }
  std::string who(const char* method) const { return fmt::format("python model \"{}\": {}", name_, method); }

  // An attribute of the instance as T; one of the wrong type is a ConfigError that names it.
  template <class T>
  T attribute(const char* attribute, const char* expected, bool (*accepted)(py::handle)) const {
    const py::object value = self().attr(attribute);
    if (accepted(value)) {
      try {
        return value.cast<T>();
      } catch (const py::cast_error&) {  // an integer beyond the type: refused below
      }
    }
    throw tsi::ConfigError("model.name", fmt::format("python model \"{}\": {} = {} ({}), expected {}", name_, attribute,
                                                     py::repr(value).cast<std::string>(),
                                                     type_name(value), expected));
  }

  // States as numpy arrays, one column per state: float64 for a real model (the real parts),
  // complex128 otherwise.
  py::object batch(tsi::ConstMatrixRef states) const {
    if (complex_) return py::cast(tsi::Matrix(states));
    return py::cast(Eigen::MatrixXd(states.real()));
  }
  py::object one(const tsi::Vector& u) const {
    if (complex_) return py::cast(u);
    return py::cast(tsi::RealVector(u.real()));
  }

  static constexpr const char* real_remedy = "return real values, or declare is_complex = True in the class";

  void store(tsi::MatrixRef out, const py::object& value, const char* method) const {
    const tsi::Matrix m = returned<tsi::Matrix>(value, who(method),
                                                fmt::format("an array of shape ({}, {}) of numbers: one column per "
                                                            "state", out.rows(), out.cols()));
    if (!complex_) check_real(value, m, who(method), real_remedy);
    if (m.rows() != out.rows() || m.cols() != out.cols())
      throw tsi::Error(fmt::format("python model \"{}\": {} returned shape ({}, {}), expected ({}, {}): one column "
                                   "per state",
                                   name_, method, m.rows(), m.cols(), out.rows(), out.cols()));
    out = m;
  }
  tsi::Vector vector(const py::object& value, const char* method) const {
    const tsi::Vector v = returned<tsi::Vector>(value, who(method), fmt::format("an array of dim = {} numbers", dim_));
    if (!complex_) check_real(value, v, who(method), real_remedy);
    if (v.size() != dim_)
      throw tsi::Error(fmt::format("python model \"{}\": {} returned {} entries, expected dim = {}", name_, method,
                                   v.size(), dim_));
    return v;
  }

  std::string name_;
  PyObject* self_;
  tsi::Index dim_ = 0;
  bool complex_ = false, has_filtered_ = false, has_derivative_ = false, hamiltonian_ = true, has_apply_A_ = false;
  double max_frequency_ = 1.0;
};

tsi::ParamSpec param_from_default(const std::string& name, const Json& value) {
  const std::string description = "a parameter of the python model";
  if (value.is_boolean()) return tsi::bool_param(name, value, description);
  if (value.is_number_integer()) return tsi::integer_param(name, value, description);
  if (value.is_number()) return tsi::number_param(name, value, description);
  if (value.is_string()) return tsi::string_param(name, value, description);
  if (value.is_array()) return tsi::array_param(name, description);
  throw tsi::ConfigError("params." + name, "got " + value.dump() + ", expected a number, integer, boolean, string or list default");
}

constexpr int max_n_tau = 1 << 20;  // as reformulation.n_tau
constexpr int max_threads = 1024;   // as the runner's --threads

// Registers (or re-registers: a notebook cell run twice) a Python class as model `name`.
void register_python_model(const std::string& name, py::object cls, const std::string& params_text,
                           const std::vector<std::string>& aliases, int n_tau, int degree, const std::string& summary) {
  if (n_tau < 2 || n_tau > max_n_tau || n_tau % 2 != 0)
    throw tsi::ConfigError("n_tau", fmt::format("got {}, expected an even integer from 2 to {}", n_tau, max_n_tau));
  if (degree < 0) throw tsi::ConfigError("nonlinearity_degree", fmt::format("got {}, expected 0 (not polynomial) or the degree", degree));
  const Json params = parse(params_text, "params");
  tsi::ModelEntry entry;
  entry.info.name = name;
  entry.info.aliases = aliases;
  entry.info.summary = summary.empty() ? "a model written in Python" : summary;
  for (const auto& [key, value] : params.items()) entry.info.params.push_back(param_from_default(key, value));
  entry.default_n_tau = n_tau;
  entry.nonlinearity_degree = degree;
  // The class is kept for the life of the process (the registry outlives the interpreter's
  // objects at exit): one reference, never released.
  PyObject* class_ref = cls.release().ptr();
  entry.create = [class_ref, name](const tsi::Params& p) -> std::unique_ptr<tsi::Model> {
    return call_python(name, "__init__", [&] {
      py::dict kwargs;
      for (const auto& [key, value] : p.raw().items())
        if (key != "eps" && key != "u0") kwargs[py::str(key)] = py::module_::import("json").attr("loads")(value.dump());
      const double eps = p.number("eps");
      py::object instance = py::handle(class_ref)(eps, **kwargs);
      return std::make_unique<PythonModel>(eps, instance, name);
    });
  };
  tsi::Registry& registry = session_registry();
  const std::string provider = "python:" + name;
  registry.remove_provider(provider);
  const std::string previous = registry.provider();
  registry.set_provider(provider);
  try {
    registry.add_model(std::move(entry));
  } catch (...) {
    registry.set_provider(previous);
    throw;
  }
  registry.set_provider(previous);
}

// ---- Fields written in Python (f(t, u) of the "matrix" model) -------------------------------

// f(t, u) as a Python callable: t a float64 array of n times, u a dim x n array (float64, or
// complex128 for a complex field), one state per column; returns an array of u's shape.
class PythonField final : public tsi::Field {
 public:
  PythonField(PyObject* function, std::string name, bool complex) : function_(function), name_(std::move(name)),
                                                                   complex_(complex) {}
  void evaluate(const tsi::RealVector& t, tsi::ConstMatrixRef states, tsi::MatrixRef out) const override {
    py::gil_scoped_acquire gil;
    try {
      py::object u = complex_ ? py::cast(tsi::Matrix(states)) : py::cast(Eigen::MatrixXd(states.real()));
      const py::object value = py::handle(function_)(py::cast(t), u);
      const std::string who = fmt::format("python field \"{}\": f(t, u)", name_);
      const tsi::Matrix m = returned<tsi::Matrix>(value, who, fmt::format("an array of u's shape ({}, {}) of numbers",
                                                                          out.rows(), out.cols()));
      if (!complex_)
        check_real(value, m, who, "return real values, or register the field with is_complex=True (tsi.solve: a "
                                  "complex u0 or A)");
      if (m.rows() != out.rows() || m.cols() != out.cols())
        throw tsi::Error(fmt::format("python field \"{}\": f(t, u) returned shape ({}, {}), expected ({}, {}): one "
                                     "column per state",
                                     name_, m.rows(), m.cols(), out.rows(), out.cols()));
      out = m;
    } catch (py::error_already_set& e) {
      throw tsi::Error(fmt::format("python field \"{}\": f(t, u): {}", name_, e.what()));
    }
  }

 private:
  PyObject* function_;  // owned by the registry entry, for the life of the process
  std::string name_;
  bool complex_;
};

// Registers (or re-registers) a Python function f(t, u) as field `name` for model.f.
void register_python_field(const std::string& name, py::object function, long dim, bool time_dependent,
                           bool is_complex, py::object u0, const std::string& summary) {
  if (!PyCallable_Check(function.ptr()))
    throw tsi::ConfigError("f", "got a value that is not callable, expected a function f(t, u)");
  if (dim < 0 || dim > tsi::max_matrix_model_dim)
    throw tsi::ConfigError("dim", fmt::format("got {}, expected 0 (any) or a size up to {}", dim, tsi::max_matrix_model_dim));
  tsi::FieldEntry entry;
  entry.info.name = name;
  entry.info.summary = summary.empty() ? "a field f(t, u) written in Python" : summary;
  entry.dim = dim;
  entry.time_dependent = time_dependent;
  entry.is_complex = is_complex;
  if (!u0.is_none()) {
    try {
      entry.initial_value = u0.cast<tsi::Vector>();
    } catch (const py::cast_error&) {
      throw tsi::ConfigError("u0", fmt::format("got {}, expected a 1-d array of numbers", described(u0)));
    }
    if (!is_complex && !(entry.initial_value.imag().array() == 0.0).all())
      throw tsi::ConfigError("u0", "has complex entries, but the field is real (is_complex=False): their imaginary "
                                   "parts would be dropped");
    if (dim != 0 && entry.initial_value.size() != dim)
      throw tsi::ConfigError("u0", fmt::format("has {} entries, expected dim = {}", entry.initial_value.size(), dim));
    if (!entry.initial_value.allFinite()) throw tsi::ConfigError("u0", "has an entry that is not finite");
  }
  PyObject* function_ref = function.release().ptr();  // kept for the life of the process
  entry.create = [function_ref, name, is_complex](tsi::Index) {
    return std::make_shared<PythonField>(function_ref, name, is_complex);
  };
  tsi::Registry& registry = session_registry();
  const std::string provider = "python-field:" + name;
  registry.remove_provider(provider);
  const std::string previous = registry.provider();
  registry.set_provider(provider);
  try {
    registry.add_field(std::move(entry));
  } catch (...) {
    registry.set_provider(previous);
    throw;
  }
  registry.set_provider(previous);
}

// ---- Runs and studies -------------------------------------------------------------------------

// The progress line of tsi.run / tsi.study (progress=True), drawn as on a terminal (one line
// rewritten with '\r', at most once a second) on Python's sys.stderr, which a notebook shows
// under its cell. The computation's threads leave the text here; the waiting thread, which
// holds the GIL, writes it (write()).
class PythonProgress {
 public:
  explicit PythonProgress(bool enabled)
      : line_(enabled ? tsi::app::ProgressMode::terminal : tsi::app::ProgressMode::off,
              [this](std::string_view text) {
                std::lock_guard<std::mutex> lock(mutex_);
                pending_ += text;
              }) {}
  tsi::app::ProgressLine& line() { return line_; }
  /// Writes what the line has drawn since the last call (the GIL held).
  void write() {
    std::string text;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      text.swap(pending_);
    }
    if (text.empty()) return;
    try {
      py::object stderr_stream = py::module_::import("sys").attr("stderr");
      stderr_stream.attr("write")(text);
      stderr_stream.attr("flush")();
    } catch (const py::error_already_set&) {  // no usable sys.stderr: the line is not shown
    }
  }
  /// Erases the line (before the result is shown).
  void finish() {
    line_.finish();
    write();
  }

 private:
  std::mutex mutex_;
  std::string pending_;
  tsi::app::ProgressLine line_;  // last: its destructor may still write to pending_
};

// A state as numpy (float64 for a real model, complex128 for a complex one, in the shape of
// its .npy file), None when there is none. States cross as arrays, never through JSON:
// result.json holds a large one only as the name of its file.
py::object state_array(const tsi::Vector& x, const tsi::app::RunOutcome& outcome) {
  if (x.size() == 0) return py::none();
  std::vector<py::ssize_t> shape;
  std::uint64_t product = 1;
  for (const std::uint64_t n : outcome.state_shape) shape.push_back(static_cast<py::ssize_t>(n)), product *= n;
  if (shape.empty() || product != static_cast<std::uint64_t>(x.size())) shape = {static_cast<py::ssize_t>(x.size())};
  if (outcome.complex_state) {
    py::array_t<std::complex<double>> a(shape);
    std::copy(x.data(), x.data() + x.size(), a.mutable_data());
    return a;
  }
  py::array_t<double> a(shape);
  double* out = a.mutable_data();
  for (tsi::Index i = 0; i < x.size(); ++i) out[i] = x(i).real();
  return a;
}

py::dict outcome_dict(const tsi::app::RunOutcome& outcome) {
  py::dict d;
  d["result"] = outcome.result.dump();
  d["csv"] = outcome.csv;
  d["ok"] = outcome.ok;
  d["message"] = outcome.message;
  d["u_final"] = state_array(outcome.u_final, outcome);
  d["reference_u_final"] = state_array(outcome.reference_u_final, outcome);
  py::list u_times;  // u at output.times, None where the run did not reach the time
  for (const tsi::Vector& u : outcome.u_times) u_times.append(state_array(u, outcome));
  d["output_times"] = outcome.output_times;
  d["u_times"] = u_times;
  return d;
}

py::dict run(const std::string& config_text, const std::string& out_dir, int threads, bool show_progress) {
  if (threads < 0 || threads > max_threads)
    throw tsi::ConfigError("threads", fmt::format("got {}, expected an integer from 1 to {} (or None: all cores)", threads,
                                                  max_threads));
  tsi::Registry& registry = session_registry();
  const Json raw = parse(config_text, "config");
  if (raw.is_object() && raw.contains("plugins")) tsi::app::load_config_plugins(loader(), raw["plugins"], "./config");
  const Json config = tsi::app::resolve_run_config(raw, registry);
  if (!out_dir.empty()) tsi::app::prepare_output_dir(out_dir);
  bool was_interrupted = false;
  // As `tsi run`: the run's tau grid on every core unless told otherwise; studies keep one
  // thread per run (their runs share the cores).
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const auto settings =
      tsi::app::RunSettings::from_flags(threads > 0 ? threads : cores, 1, tsi::app::default_max_steps);
  PythonProgress progress(show_progress);
  tsi::app::StepProgressLine steps(progress.line());
  const auto outcome = interruptible<tsi::app::RunOutcome>(
      [&] {
        return tsi::app::execute_run(config, registry, settings,
                                     show_progress ? tsi::app::ProgressFn(std::ref(steps)) : nullptr);
      },
      was_interrupted, [&] { progress.write(); });
  progress.finish();
  if (!out_dir.empty()) tsi::app::write_run_files(out_dir, outcome);
  py::dict d = outcome_dict(outcome);
  d["interrupted"] = was_interrupted;
  return d;
}

py::dict study(const std::string& spec_text, int jobs, const std::vector<std::string>& overrides,
               const std::string& out_dir, bool show_progress) {
  if (jobs < 0 || jobs > max_threads)
    throw tsi::ConfigError("jobs", fmt::format("got {}, expected an integer from 1 to {} (0 or None: all cores)", jobs,
                                               max_threads));
  tsi::Registry& registry = session_registry();
  const Json spec = parse(spec_text, "study");
  if (spec.is_object() && spec.contains("base") && spec["base"].is_object() && spec["base"].contains("plugins"))
    tsi::app::load_config_plugins(loader(), spec["base"]["plugins"], "./study");
  const tsi::app::Study expanded = tsi::app::expand_study(spec, registry, overrides);
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (!out_dir.empty()) tsi::app::prepare_output_dir(out_dir);
  bool was_interrupted = false;
  const auto start = std::chrono::steady_clock::now();
  PythonProgress progress(show_progress);
  const auto outcomes = interruptible<std::vector<tsi::app::RunOutcome>>(
      [&] {
        return tsi::app::run_study(expanded, registry, jobs,
                                   show_progress ? tsi::app::study_progress(progress.line()) : nullptr);
      },
      was_interrupted, [&] { progress.write(); });
  progress.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const Json rows = tsi::app::study_rows(expanded, outcomes);
  if (!out_dir.empty()) tsi::app::write_study_files(out_dir, expanded, outcomes, rows, wall, jobs);
  Json head = {{"kind", expanded.kind}, {"title", expanded.title}, {"study", expanded.spec},
               {"varied", expanded.varied}, {"table", rows}, {"wall_seconds", wall}, {"jobs", jobs},
               {"tsi_version", tsi::version_string}, {"not_used", expanded.not_used}};
  if (expanded.kind == "convergence") head["convergence"] = tsi::app::convergence_summary(rows);
  if (expanded.kind == "work-precision") head["work_at_error"] = tsi::app::work_at_error(rows, {1e-4, 1e-6});
  py::list runs;
  for (size_t i = 0; i < outcomes.size(); ++i) {
    py::dict r = outcome_dict(outcomes[i]);
    r["id"] = expanded.runs[i].id;
    r["label"] = expanded.runs[i].label;
    r["assignments"] = expanded.runs[i].assignments.dump();
    runs.append(r);
  }
  py::dict d;
  d["study"] = head.dump();
  d["runs"] = runs;
  d["interrupted"] = was_interrupted;
  return d;
}

// The exception classes: tsi.Error, and under it tsi.ConfigError (with .field) and
// tsi.PluginError. Created once at import and kept for the life of the process.
PyObject* error_type = nullptr;
PyObject* config_error_type = nullptr;
PyObject* plugin_error_type = nullptr;

void translate(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const tsi::ConfigError& e) {
    py::object instance = py::handle(config_error_type)(e.what());
    instance.attr("field") = e.field();
    PyErr_SetObject(config_error_type, instance.ptr());
  } catch (const tsi::PluginError& e) {
    PyErr_SetString(plugin_error_type, e.what());
  } catch (const tsi::Error& e) {
    PyErr_SetString(error_type, e.what());
  }
}

}  // namespace

PYBIND11_MODULE(_tsi, m) {
  m.doc() = "tsi's native module: use the package tsi";
  m.attr("version") = tsi::version_string;
  // The limits the package checks arguments against before it calls in.
  m.attr("max_matrix_model_dim") = tsi::max_matrix_model_dim;
  m.attr("max_output_times") = tsi::app::max_output_times;
  m.attr("max_steps") = tsi::app::default_max_steps;

  error_type = PyErr_NewExceptionWithDoc("tsi.Error", "An error tsi reports.", PyExc_RuntimeError, nullptr);
  config_error_type =
      PyErr_NewExceptionWithDoc("tsi.ConfigError", "Bad input; .field names the config path.", error_type, nullptr);
  plugin_error_type = PyErr_NewExceptionWithDoc("tsi.PluginError", "A plugin that could not be loaded or registered.",
                                                error_type, nullptr);
  m.add_object("Error", py::handle(error_type));
  m.add_object("ConfigError", py::handle(config_error_type));
  m.add_object("PluginError", py::handle(plugin_error_type));
  py::register_exception_translator(&translate);

  m.def(
      "init",
      [] {
        tsi::Registry& registry = session_registry();
        return tsi::app::load_plugins(loader(), registry, {});
      },
      "Registers the core and loads the shipped plugins and TSI_PLUGIN_PATH; returns the warnings.");
  m.def("list", [](const std::string& what) { return tsi::app::list_json(session_registry(), what).dump(); },
        py::arg("what") = "");
  m.def("load_plugin", [](const std::string& path) { loader().load(path); }, py::arg("path"));
  m.def("plugin_directory", &tsi::PluginLoader::default_directory);
  m.def("run", &run, py::arg("config"), py::arg("out") = "", py::arg("threads") = 0, py::arg("progress") = false);
  m.def("study", &study, py::arg("spec"), py::arg("jobs") = 0, py::arg("overrides") = std::vector<std::string>(),
        py::arg("out") = "", py::arg("progress") = false);
  m.def("register_field", &register_python_field, py::arg("name"), py::arg("f"), py::arg("dim") = 0,
        py::arg("time_dependent") = false, py::arg("is_complex") = false, py::arg("u0") = py::none(),
        py::arg("summary") = "");
  m.def("register_model", &register_python_model, py::arg("name"), py::arg("cls"), py::arg("params") = "{}",
        py::arg("aliases") = std::vector<std::string>(), py::arg("n_tau") = 64, py::arg("nonlinearity_degree") = 0,
        py::arg("summary") = "");
}
