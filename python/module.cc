// The C++ extension `hybrid._hybrid` behind the Python package `hybrid` (python/hybrid/,
// docs/python.md): the finger's closed form, vectorised, and models read, drawn, simulated and
// checked in-process. JSON-shaped results travel as JSON text (the same documents as the command
// line's --json); python/hybrid/__init__.py turns them into Python values.
//
// Ctrl-C. Long calls (Model.check, Model.simulate, diagnose) run in a child process (fork) while
// the calling thread, without the GIL, waits for its answer and checks for Python signals every
// 50 ms: on an exception from a signal handler (KeyboardInterrupt) the child is killed and the
// exception raised, so the engines stop at once although they have no way to be cancelled
// (docs/python.md). finger_angles checks for signals between blocks of positions.
//
// Errors. The commands' messages refer to their arguments by API names (commands/
// argument_message.h), which are this module's keyword arguments: what() is the message in those
// words. cli::OptionError becomes a ValueError with the attribute `argument`, the other command
// errors and std::invalid_argument ValueError, hybrid::InternalError (a bug) RuntimeError.

#include <fcntl.h>
#include <poll.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "automaton/internal_assert.h"
#include "commands/bundled_files.h"
#include "commands/check_command.h"
#include "commands/command_error.h"
#include "commands/diagnose_model_command.h"
#include "commands/info_command.h"
#include "commands/initial_values.h"
#include "commands/model_file.h"
#include "commands/output.h"
#include "commands/simulate_command.h"
#include "gripper/commands/diagnose_command.h"
#include "gripper/commands/grasp_sweep.h"
#include "gripper/commands/gripper_command.h"
#include "hybrid/automaton/dot_writer.h"
#include "hybrid/automaton/log.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"
#include "hybrid/gripper/finger_closed_form.h"
#include "hybrid/gripper/finger_parameters.h"
#include "hybrid/gripper/gripper_emulator.h"
#include "hybrid/gripper/measured_data.h"
#include "hybrid/model_diagnosis/trace_data.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/spaceex/spaceex_import.h"

namespace py = pybind11;

namespace hybrid::python {
namespace {

using gripper::FingerClosedForm;
using gripper::FingerContacts;
using gripper::FingerParameters;

// `value` as a motor position of argument `name`; throws OptionError (ValueError) outside
// [0, 255].
double MotorPosition(const std::string& name, double value) {
  if (!(value >= 0.0 && value <= 255.0)) {
    throw cli::OptionError(name, cli::Arg(name) + " must be a motor position in [0, 255] (got " +
                                     std::to_string(value) + ")");
  }
  return value;
}

// The closed form's constants of the finger model at `path` (spec/finger.ha or one like it).
FingerParameters ParametersOfModel(const std::string& path) {
  const System model = spaceex::ReadModelFile(path);
  if (model.components().size() != 1) {
    throw cli::OptionError("model", path + ": not a finger model like spec/finger.ha (it has " +
                                        std::to_string(model.components().size()) + " components)");
  }
  try {
    const FingerParameters p = gripper::FingerParametersOf(model.components()[0].automaton);
    FingerClosedForm check({}, p);  // the closed form's own conditions on its constants
    return p;
  } catch (const std::invalid_argument& e) {
    throw cli::OptionError("model", path + ": " + e.what());
  }
}

// The closed form's angles at the positions `g` into `theta` (3 per position), in two halves on
// two threads for large blocks (the closed form is read-only, so they share it); false if a
// position is outside [0, 255] (the kernel checks the range in the same pass).
bool AnglesOfBlock(const FingerClosedForm& closed, std::span<const double> g,
                   std::span<double> theta) {
  const auto angles = [&closed](std::span<const double> part, std::span<double> to, bool* failed) {
    try {
      closed.AnglesAt(part, to);
    } catch (const std::out_of_range&) {
      *failed = true;
    }
  };
  constexpr size_t kThreadBatch = 1 << 16;  // below this a thread costs more than it saves
  bool failed = false;
  if (g.size() < kThreadBatch) {
    angles(g, theta, &failed);
    return !failed;
  }
  const size_t half = g.size() / 2;
  bool first_failed = false;
  std::thread first(angles, g.first(half), theta.first(3 * half), &first_failed);
  angles(g.subspan(half), theta.subspan(3 * half), &failed);
  first.join();
  return !failed && !first_failed;
}

// finger_angles: theta1..3 (degrees) at every g, shape (n, 3), computed without the GIL in blocks
// of 2^22 positions (a few milliseconds each), checking for Python signals (Ctrl-C) after each.
py::array_t<double> FingerAngles(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& g,
    std::optional<double> gob1, std::optional<double> gob2, std::optional<double> gob3,
    const std::optional<std::string>& model, const std::optional<py::array>& out_array) {
  FingerContacts contacts;
  const std::array<std::optional<double>, 3> gob = {gob1, gob2, gob3};
  for (int i = 0; i < 3; ++i) {
    if (gob[i]) contacts.gob[i] = MotorPosition("gob" + std::to_string(i + 1), *gob[i]);
  }
  const FingerClosedForm closed(contacts, model ? ParametersOfModel(*model) : FingerParameters{});
  const size_t n = static_cast<size_t>(g.size());
  const std::span<const double> in(g.data(), n);
  py::array_t<double> out;
  if (out_array) {
    // Written in place: it must be exactly what the answer would be (no conversion, no copy).
    const py::array& a = *out_array;
    if (!a.dtype().is(py::dtype::of<double>()) || a.ndim() != 2 ||
        a.shape(0) != static_cast<py::ssize_t>(n) || a.shape(1) != 3 ||
        !(a.flags() & py::array::c_style) || !a.writeable()) {
      throw cli::OptionError("out", cli::Arg("out") + " must be a writable C-contiguous float64 " +
                                        "array of shape (" + std::to_string(n) + ", 3)");
    }
    out = py::reinterpret_borrow<py::array_t<double>>(a);
  } else {
    out = py::array_t<double>({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
  }
  const std::span<double> theta(out.mutable_data(), 3 * n);
  constexpr size_t kBlock = size_t{1} << 22;
  for (size_t start = 0; start < n; start += kBlock) {
    const size_t count = std::min(kBlock, n - start);
    bool in_range = true;
    {
      py::gil_scoped_release release;
      in_range =
          AnglesOfBlock(closed, in.subspan(start, count), theta.subspan(3 * start, 3 * count));
    }
    if (!in_range) {
      for (const double x : in) MotorPosition("g", x);  // throws, naming the first one outside
    }
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
  return out;
}

// finger_angles of one motor position without a model: FingerAngles' answer without the batch
// machinery (no array conversion, no blocks), the closed form of the last contacts kept per
// thread.
py::array_t<double> FingerAnglesOne(double g, std::optional<double> gob1,
                                    std::optional<double> gob2, std::optional<double> gob3) {
  FingerContacts contacts;
  const std::array<std::optional<double>, 3> gob = {gob1, gob2, gob3};
  for (int i = 0; i < 3; ++i) {
    if (gob[i]) contacts.gob[i] = MotorPosition("gob" + std::to_string(i + 1), *gob[i]);
  }
  thread_local std::optional<FingerClosedForm> last;
  if (!last || last->contacts().gob != contacts.gob) last.emplace(contacts);
  MotorPosition("g", g);
  py::array_t<double> out({py::ssize_t{1}, py::ssize_t{3}});
  last->AnglesAt(std::span<const double>(&g, 1), std::span<double>(out.mutable_data(), 3));
  return out;
}

// An input's signal from Python: a number (constant), a list of (time, value) pairs (steps), or
// a signal in the language's syntax ("step(0: 0, 1: 0.5)", docs/language.md).
using SignalValue = std::variant<double, std::vector<std::pair<double, double>>, std::string>;

InputSignal SignalOf(const std::string& name, const SignalValue& value) {
  InputSignal s;
  if (const double* c = std::get_if<double>(&value)) {
    s.points = {{0.0, *c}};
  } else if (const auto* points = std::get_if<std::vector<std::pair<double, double>>>(&value)) {
    if (points->empty()) {
      throw cli::OptionError("inputs", cli::Arg("inputs") + "['" + name + "']: no points");
    }
    s.points = *points;
  } else {
    s = ParseSignal(std::get<std::string>(value), "inputs['" + name + "']");
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Bytes a child process sends back: numbers and strings appended to a std::string and read back
// in the same order.

class Encoder {
 public:
  void Number(std::uint64_t v) { Raw(&v, sizeof v); }
  void Text(std::string_view v) {
    Number(v.size());
    out_.append(v);
  }
  void Doubles(std::span<const double> v) { Raw(v.data(), v.size() * sizeof(double)); }
  std::string Take() { return std::move(out_); }

 private:
  void Raw(const void* p, std::size_t n) { out_.append(static_cast<const char*>(p), n); }
  std::string out_;
};

class Decoder {
 public:
  explicit Decoder(std::string_view in) : in_(in) {}
  std::uint64_t Number() {
    std::uint64_t v = 0;
    std::memcpy(&v, Take(sizeof v).data(), sizeof v);
    return v;
  }
  std::string Text() { return std::string(Take(Number())); }
  void Doubles(std::span<double> to) {
    const std::string_view bytes = Take(to.size() * sizeof(double));
    if (!to.empty()) std::memcpy(to.data(), bytes.data(), bytes.size());
  }

 private:
  std::string_view Take(std::size_t n) {
    if (n > in_.size() - at_) throw std::runtime_error("truncated answer from the worker process");
    const std::string_view part = in_.substr(at_, n);
    at_ += n;
    return part;
  }
  std::string_view in_;
  std::size_t at_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Long calls in a child process that Ctrl-C stops.

// A job's answer: its result, or the exception it threw (reconstructed by DecodeOrRethrow).
enum Outcome : char {
  kResult = 'R',
  kModelError = 'M',   // hybrid::ParseError: file, line, column, message
  kDataError = 'D',    // hybrid::DataError: source, line, column, message
  kOptionError = 'O',  // cli::OptionError (ValueError naming the argument): argument, message
  kValueError = 'V',   // a bad argument or input (ValueError): its message
  kMemoryError = 'N',
  kInternalError = 'I',  // hybrid::InternalError (RuntimeError): its message
  kOtherError = 'E',     // anything else (RuntimeError): its message
};

// Runs `job` and encodes what came of it: the Outcome, then the result or the exception's fields.
std::string RunAndEncode(const std::function<std::string()>& job) {
  Encoder e;
  const auto located = [&e](Outcome kind, const std::string& file, int line, int column,
                            const std::string& message) {
    e.Number(kind);
    e.Text(file);
    e.Number(static_cast<std::uint64_t>(line));
    e.Number(static_cast<std::uint64_t>(column));
    e.Text(message);
  };
  try {
    std::string result = job();
    e.Number(kResult);
    e.Text(result);
  } catch (const ParseError& x) {
    located(kModelError, x.file(), x.line(), x.column(), x.message());
  } catch (const DataError& x) {
    located(kDataError, x.source(), x.line(), x.column(), x.message());
  } catch (const std::bad_alloc&) {
    e.Number(kMemoryError);
  } catch (const cli::OptionError& x) {
    e.Number(kOptionError);
    e.Text(x.argument());
    e.Text(x.what());
  } catch (const InternalError& x) {
    e.Number(kInternalError);
    e.Text(x.what());
  } catch (const std::invalid_argument& x) {
    e.Number(kValueError);
    e.Text(x.what());
  } catch (const cli::InputError& x) {
    e.Number(kValueError);
    e.Text(x.what());
  } catch (const std::out_of_range& x) {
    e.Number(kValueError);
    e.Text(x.what());
  } catch (const std::exception& x) {
    e.Number(kOtherError);
    e.Text(x.what());
  } catch (...) {
    e.Number(kOtherError);
    e.Text("unknown error");
  }
  return e.Take();
}

// The result RunAndEncode encoded in `answer`; throws the exception it encoded instead (as the
// same C++ type where it matters, so that the module's translator gives the same Python
// exception as a call in this process).
std::string DecodeOrRethrow(std::string_view answer) {
  Decoder d(answer);
  const auto kind = static_cast<Outcome>(d.Number());
  if (kind == kResult) return d.Text();
  if (kind == kModelError || kind == kDataError) {
    const std::string file = d.Text();
    const int line = static_cast<int>(d.Number());
    const int column = static_cast<int>(d.Number());
    const std::string message = d.Text();
    if (kind == kModelError) throw ParseError(file, line, column, message);
    throw DataError(file, line, column, message);
  }
  if (kind == kMemoryError) throw std::bad_alloc();
  if (kind == kOptionError) {
    std::string argument = d.Text();
    throw cli::OptionError(std::move(argument), d.Text());
  }
  if (kind == kValueError) throw std::invalid_argument(d.Text());
  if (kind == kInternalError) throw InternalError(d.Text());
  throw std::runtime_error(d.Text());
}

// Writes all of `bytes` to `fd`; false if it cannot.
bool WriteAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

// The child process: runs `job` and sends its answer (length, then RunAndEncode's bytes) to `fd`,
// then ends without running any exit handler (the interpreter's are the parent's). It never
// touches Python. Signals that stop a program stop it (the parent's Python handlers are reset),
// and on Linux it dies with its parent.
[[noreturn]] void ChildMain(const std::function<std::string()>& job, int fd, pid_t parent) {
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
    ::signal(s, SIG_DFL);
    sigaddset(&signals, s);
  }
  pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);
#if defined(__linux__)
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(1);
  // Only the standard streams and the answer's pipe stay open: a pipe the parent writes stays
  // its own to close (its reader sees the end when the parent closes it), and a signal's wakeup
  // byte (signal.set_wakeup_fd) never reaches the parent's event loop.
  std::vector<int> open_fds;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", ec)) {
    open_fds.push_back(std::atoi(entry.path().filename().c_str()));
  }
  for (const int other : open_fds) {
    if (other > 2 && other != fd) ::close(other);
  }
#endif
  std::string answer;
  try {
    // A thread of its own: the parent's thread-local state (the parser's stack thread) does not
    // survive fork().
    std::thread worker([&] { answer = RunAndEncode(job); });
    worker.join();
  } catch (const std::system_error&) {
    answer = RunAndEncode(job);
  }
  Encoder header;
  header.Number(answer.size());
  ::_exit(WriteAll(fd, header.Take()) && WriteAll(fd, answer) ? 0 : 1);
}

// A child process running a job, and the reading end of the pipe of its answer. Killed (if it
// still runs) and reaped when destroyed.
class Child {
 public:
  Child(pid_t pid, int fd) : pid_(pid), fd_(fd) {}
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      Reap();
    }
    ::close(fd_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // The child's answer. Waits without the GIL, checking for Python signals every 50 ms: throws
  // py::error_already_set when a handler raised (KeyboardInterrupt), KeyboardInterrupt when
  // SIGINT ended the child, std::runtime_error when it ended otherwise without an answer.
  std::string Answer() {
    std::string bytes;
    for (;;) {
      bool ended = false;
      {
        py::gil_scoped_release release;
        ended = Read(&bytes);
      }
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (bytes.size() >= sizeof(std::uint64_t)) {
        const std::uint64_t size = Decoder(bytes).Number();
        if (bytes.size() - sizeof(std::uint64_t) >= size) {
          return bytes.substr(sizeof(std::uint64_t), size);
        }
      }
      if (ended) ThrowEnded();
    }
  }

 private:
  // Appends what the pipe holds to `bytes`, waiting at most 50 ms for it; true at its end.
  bool Read(std::string* bytes) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) return false;
    char buffer[1 << 16];
    for (int reads = 0; reads < 256; ++reads) {  // up to 16 MiB before checking for signals
      const ssize_t n = ::read(fd_, buffer, sizeof buffer);
      if (n == 0) return true;
      if (n < 0) return errno != EINTR && errno != EAGAIN;
      bytes->append(buffer, static_cast<std::size_t>(n));
    }
    return false;
  }

  // Waits for the child to end; its wait status (0 if another waiter reaped it).
  int Reap() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    return status;
  }

  [[noreturn]] void ThrowEnded() {
    const int status = Reap();
    if (WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
      throw py::error_already_set();
    }
    throw std::runtime_error(WIFSIGNALED(status)
                                 ? "the computation's process was killed by signal " +
                                       std::to_string(WTERMSIG(status))
                                 : "the computation's process ended without an answer");
  }

  pid_t pid_;
  int fd_;
};

// Whether this is the interpreter's main thread, the one Python signal handlers run on.
bool OnMainThread() {
  const py::module_ threading = py::module_::import("threading");
  const py::object main_ident = threading.attr("main_thread")().attr("ident");
  return main_ident.equal(threading.attr("get_ident")());
}

// `job()` (which must not touch Python objects: it may run in another process), so that Ctrl-C
// stops it within 50 ms: on the main thread in a child process (fork) while this thread waits
// without the GIL (see Child::Answer); elsewhere, where no signal handler runs, or when no
// process can be made, here without the GIL. Throws what the job throws.
std::string RunStoppable(const std::function<std::string()>& job) {
  int fds[2] = {-1, -1};
  if (OnMainThread() && ::pipe2(fds, O_CLOEXEC) == 0) {
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::close(fds[0]);
      ChildMain(job, fds[1], parent);
    }
    ::close(fds[1]);
    if (pid > 0) {
      ::fcntl(fds[0], F_SETFL, ::fcntl(fds[0], F_GETFL) | O_NONBLOCK);
      Child child(pid, fds[0]);
      const std::string answer = child.Answer();
      return DecodeOrRethrow(answer);
    }
    ::close(fds[0]);
  }
  py::gil_scoped_release release;
  return job();
}

// A model read from a file (.ha or SpaceEx .xml), with the operations of the command line.
class Model {
 public:
  // `config`: a SpaceEx configuration in place of the model's .cfg (commands/model_file.h).
  Model(std::string path, const std::optional<std::string>& config)
      : path_(std::move(path)), system_(cli::ReadModelArgument(path_, config.value_or(""))) {}

  const std::string& path() const { return path_; }
  const std::string& name() const { return system_.name(); }
  std::string InfoJsonText() const { return cli::InfoJson(system_, path_).dump(); }
  std::string Dot(bool product) const {
    DotOptions options;
    options.product = product;
    return WriteDot(system_, options);
  }

  std::string CheckJsonText(const std::vector<std::string>& properties, const std::string& method,
                            double budget, int depth) const {
    cli::CheckArgs args;
    args.model = path_;
    args.properties = properties;
    args.method = method;
    args.budget = budget;
    args.depth = depth;
    return RunStoppable([&] { return cli::CheckReport(args, system_, nullptr).dump(); });
  }

  // The flowpipe's boxes (hybrid.Model.reach_set): variables, modes, times and bounds as arrays.
  py::dict ReachSet(const std::vector<std::string>& names, double budget, int order,
                    double step) const {
    std::vector<Property> chosen;
    for (const Property& p : system_.properties()) {
      if (names.empty() || std::find(names.begin(), names.end(), p.name) != names.end()) {
        chosen.push_back(p);
      }
    }
    if (!(budget > 0) || !(budget <= 1e6))
      throw std::invalid_argument("budget must be in (0, 1e6]");
    FlowpipeReachability::Options options;
    options.max_steps =
        static_cast<std::int64_t>(std::ceil(budget * kFlowpipeStepsPerBudgetSecond));
    options.max_entries = std::max(50, static_cast<int>(budget * kFlowpipeEntriesPerBudgetSecond));
    options.order = order;
    options.step = step;
    std::string why;
    if (!FlowpipeReachability::Handles(system_, chosen, &why)) {
      throw std::invalid_argument("no flowpipe for this model: " + why);
    }
    // The job may run in a child process (RunStoppable): the set comes back as text, one box per
    // line (mode, then the numbers in hexadecimal floating point, exact).
    const std::string text = RunStoppable([&] {
      FlowpipeReachability::ReachSet set;
      FlowpipeReachability(options).Check(system_, chosen, nullptr, &set);
      std::ostringstream out;
      out << std::hexfloat;
      for (const std::string& v : set.variables) out << v << '\t';
      out << '\n';
      for (const auto& b : set.boxes) {
        out << b.mode << '\t' << b.t_lo << ' ' << b.t_hi;
        for (const auto& [l, h] : b.box) out << ' ' << l << ' ' << h;
        out << '\n';
      }
      return out.str();
    });
    FlowpipeReachability::ReachSet set;
    std::istringstream in(text);
    std::string line;
    std::getline(in, line);
    for (std::size_t begin = 0, end; (end = line.find('\t', begin)) != std::string::npos;
         begin = end + 1) {
      set.variables.push_back(line.substr(begin, end - begin));
    }
    while (std::getline(in, line)) {
      const std::size_t tab = line.find('\t');
      FlowpipeReachability::ReachBox b;
      b.mode = line.substr(0, tab);
      const char* p = line.c_str() + tab + 1;
      char* next = nullptr;
      b.t_lo = std::strtod(p, &next);
      b.t_hi = std::strtod(next, &next);
      for (std::size_t j = 0; j < set.variables.size(); ++j) {
        const double l = std::strtod(next, &next);
        const double h = std::strtod(next, &next);
        b.box.emplace_back(l, h);
      }
      set.boxes.push_back(std::move(b));
    }
    const auto n = static_cast<py::ssize_t>(set.boxes.size());
    const auto v = static_cast<py::ssize_t>(set.variables.size());
    py::array_t<double> time({n, static_cast<py::ssize_t>(2)});
    py::array_t<double> lo({n, v}), hi({n, v});
    auto tt = time.mutable_unchecked<2>();
    auto l = lo.mutable_unchecked<2>();
    auto h = hi.mutable_unchecked<2>();
    py::list modes;
    for (py::ssize_t i = 0; i < n; ++i) {
      const auto& b = set.boxes[static_cast<std::size_t>(i)];
      tt(i, 0) = b.t_lo;
      tt(i, 1) = b.t_hi;
      for (py::ssize_t j = 0; j < v; ++j) {
        l(i, j) = b.box[static_cast<std::size_t>(j)].first;
        h(i, j) = b.box[static_cast<std::size_t>(j)].second;
      }
      modes.append(b.mode);
    }
    py::dict out;
    out["variables"] = set.variables;
    out["mode"] = modes;
    out["time"] = time;
    out["lo"] = lo;
    out["hi"] = hi;
    return out;
  }

  py::dict Simulate(std::optional<double> until, const std::map<std::string, SignalValue>& inputs,
                    std::optional<double> sample, const std::map<std::string, double>& parameters,
                    const std::map<std::string, double>& init,
                    std::optional<double> tolerance) const;

 private:
  std::vector<InputSignal> Signals(const std::map<std::string, SignalValue>& inputs) const;

  // The simulator of system_, compiled on the first run and kept (Simulator::Run is const and
  // reentrant: each run has its own state).
  const Simulator& CachedSimulator() const;

  std::string path_;
  System system_;
  mutable std::once_flag simulator_once_;
  mutable std::unique_ptr<Simulator> simulator_;
};

const Simulator& Model::CachedSimulator() const {
  std::call_once(simulator_once_, [&] { simulator_ = std::make_unique<Simulator>(system_); });
  return *simulator_;
}

std::vector<InputSignal> Model::Signals(const std::map<std::string, SignalValue>& inputs) const {
  std::vector<InputSignal> signals;
  for (const auto& [name, value] : inputs) {
    const auto slot = system_.symbols().Find(name);
    if (!slot || system_.symbols()[*slot].kind != SymbolKind::kInput) {
      throw py::key_error("'" + name + "' is not an input of the model");
    }
    InputSignal s = SignalOf(name, value);
    s.slot = *slot;
    signals.push_back(std::move(s));
  }
  return signals;
}

// Encodes what Model.simulate returns of run `r` (decoded by RunDict in the parent): the number of
// samples n, their times, the number of variables and each one's name and n values, the mode
// labels (a table of the distinct ones, then one index per sample) and
// the command's JSON report (for `horizon`).
std::string EncodedRun(const Simulator& sim, const SimulationResult& r, double horizon) {
  const std::size_t n = r.samples.size();
  Encoder e;
  e.Number(n);
  std::vector<double> column(n);
  for (std::size_t k = 0; k < n; ++k) column[k] = r.samples[k].time;
  e.Doubles(column);
  e.Number(sim.variable_names().size());
  for (std::size_t v = 0; v < sim.variable_names().size(); ++v) {
    e.Text(sim.variable_names()[v]);
    for (std::size_t k = 0; k < n; ++k) column[k] = r.samples[k].x[v];
    e.Doubles(column);
  }
  std::vector<std::string> labels;
  std::unordered_map<std::string, std::uint64_t> label_index;
  std::vector<std::uint64_t> mode_of(n);
  for (std::size_t k = 0; k < n; ++k) {
    std::string label = sim.ModeLabel(r.samples[k].modes);
    const auto [it, added] = label_index.emplace(label, labels.size());
    if (added) labels.push_back(std::move(label));
    mode_of[k] = it->second;
  }
  e.Number(labels.size());
  for (const std::string& label : labels) e.Text(label);
  for (const std::uint64_t m : mode_of) e.Number(m);
  e.Text(cli::SimulationReport(sim, r, horizon).dump());
  return e.Take();
}

// A number as the JSON report gives it to Python: a float, or None where JSON has null (a value
// that is not finite).
py::object ReportNumber(double v) {
  return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none());
}

// {variable name: value} of state `x`; `names` are the simulator's variable names as Python
// strings.
py::dict StateDict(const std::vector<py::str>& names, const Eigen::VectorXd& x) {
  py::dict out;
  for (std::size_t i = 0; i < names.size(); ++i) out[names[i]] = ReportNumber(x[i]);
  return out;
}

// The members of `hybrid simulate --json` (cli::SimulationReport: status, message, until, final,
// steps, events, zeno) as Python objects, put in `out`: the same members and values as the JSON
// text read by Python's json module (tests/python/test_hybrid.py compares them with the program's
// output), built without the text.
void AddReport(const Simulator& sim, const SimulationResult& r, double until, py::dict& out) {
  std::vector<py::str> names;
  for (const std::string& name : sim.variable_names()) names.emplace_back(name);
  out["status"] = py::str(std::string(StatusName(r.status)));
  out["message"] = py::str(r.message);
  out["until"] = ReportNumber(until);
  const StateSample& last = r.samples.back();
  py::dict final_state;
  final_state["time"] = ReportNumber(last.time);
  final_state["mode"] = py::str(sim.ModeLabel(last.modes));
  final_state["values"] = StateDict(names, last.x);
  out["final"] = final_state;
  out["steps"] = py::int_(r.steps);
  py::list events(r.events.size());
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const EventRecord& e = r.events[i];
    py::dict event;
    event["time"] = ReportNumber(e.time);
    event["cause"] = py::str(cli::EventCauseName(e.cause));
    event["transitions"] = py::cast(e.transitions);
    event["label"] = py::str(e.label);
    event["mode_before"] = py::str(sim.ModeLabel(e.modes_before));
    event["mode_after"] = py::str(sim.ModeLabel(e.modes_after));
    event["before"] = StateDict(names, e.before);
    event["after"] = StateDict(names, e.after);
    events[i] = event;
  }
  out["events"] = events;
  if (r.zeno) {
    py::dict zeno;
    zeno["accumulation_time"] = ReportNumber(r.zeno->accumulation_time);
    zeno["cycle"] = py::cast(r.zeno->cycle);
    out["zeno"] = zeno;
  }
}

// The dict Model.simulate returns, built from run `r` in this process: AddReport's members, and
// the trajectory as `time` (numpy), `states` ({name: numpy array}) and `modes` (one label per
// instant, the distinct labels made once).
py::dict RunDictOf(const Simulator& sim, const SimulationResult& r, double horizon) {
  const auto n = static_cast<py::ssize_t>(r.samples.size());
  py::dict out;
  AddReport(sim, r, horizon, out);
  py::array_t<double> time(n);
  double* t = time.mutable_data();
  for (py::ssize_t k = 0; k < n; ++k) t[k] = r.samples[k].time;
  out["time"] = time;
  py::dict states;
  for (std::size_t v = 0; v < sim.variable_names().size(); ++v) {
    py::array_t<double> column(n);
    double* c = column.mutable_data();
    for (py::ssize_t k = 0; k < n; ++k) c[k] = r.samples[k].x[v];
    states[py::str(sim.variable_names()[v])] = column;
  }
  out["states"] = states;
  py::list modes(n);
  const std::vector<int>* previous = nullptr;
  py::str label;
  for (py::ssize_t k = 0; k < n; ++k) {
    if (previous == nullptr || *previous != r.samples[k].modes) {
      label = py::str(sim.ModeLabel(r.samples[k].modes));
      previous = &r.samples[k].modes;
    }
    modes[k] = label;
  }
  out["modes"] = modes;
  return out;
}

// The dict Model.simulate returns, from EncodedRun's bytes (a run in the child process).
py::dict RunDict(std::string_view encoded) {
  Decoder d(encoded);
  const auto n = static_cast<py::ssize_t>(d.Number());
  py::array_t<double> time(n);
  d.Doubles({time.mutable_data(), static_cast<std::size_t>(n)});
  py::dict states;
  for (std::uint64_t v = d.Number(); v > 0; --v) {
    const std::string name = d.Text();
    py::array_t<double> column(n);
    d.Doubles({column.mutable_data(), static_cast<std::size_t>(n)});
    states[py::str(name)] = column;
  }
  std::vector<py::str> labels;
  for (std::uint64_t m = d.Number(); m > 0; --m) labels.emplace_back(d.Text());
  py::list modes(n);
  for (py::ssize_t k = 0; k < n; ++k) modes[k] = labels.at(d.Number());
  // The report's members from its JSON text (as the quick path's AddReport builds them).
  py::dict out = py::module_::import("json").attr("loads")(py::str(d.Text()));
  out["time"] = time;
  out["states"] = states;
  out["modes"] = modes;
  return out;
}

py::dict Model::Simulate(std::optional<double> until,
                         const std::map<std::string, SignalValue>& inputs,
                         std::optional<double> sample,
                         const std::map<std::string, double>& parameters,
                         const std::map<std::string, double>& init,
                         std::optional<double> tolerance) const {
  SimulationOptions options;
  options.until = until;
  if (sample) options.sample_step = *sample;
  if (tolerance) {
    options.relative_tolerance = *tolerance;
    options.absolute_tolerance = *tolerance * 1e-2;
  }
  for (const auto& [name, value] : parameters) options.parameters.emplace_back(name, value);
  const std::vector<InputSignal> signals = Signals(inputs);
  const double horizon = until ? *until : system_.scenario() ? system_.scenario()->until : 0.0;
  // The kept simulator, or, with initial values, one of a copy of the model that has them
  // (commands/initial_values.h).
  std::optional<System> with_init;
  std::optional<Simulator> own;
  if (!init.empty()) {
    with_init.emplace(system_);
    cli::SetInitialValues({init.begin(), init.end()}, *with_init);
    own.emplace(*with_init);
  }
  const Simulator& sim = own ? *own : CachedSimulator();
  // First here, without the GIL, for at most kQuickPasses passes of the integration loop: a short
  // run (most are) costs no process. A run that needs more is run again from the start where
  // Ctrl-C can stop it (RunStoppable), so that no long computation ignores Ctrl-C.
  constexpr long kQuickPasses = 20000;
  SimulationOptions quick = options;
  quick.max_steps = std::min(options.max_steps, kQuickPasses);
  std::optional<SimulationResult> result;
  {
    py::gil_scoped_release release;
    result = sim.Run(quick, signals);
  }
  if (result->status == SimulationStatus::kStepLimit && options.max_steps > kQuickPasses) {
    return RunDict(
        RunStoppable([&] { return EncodedRun(sim, sim.Run(options, signals), horizon); }));
  }
  return RunDictOf(sim, *result, horizon);
}

// The arguments of `hybrid hand` from hybrid.hand's keyword arguments.
cli::HandArgs HandArgsOf(const std::vector<std::string>& objects, const std::string& mode,
                         std::optional<double> spread, double g, std::optional<double> g_a,
                         std::optional<double> g_b, std::optional<double> g_c) {
  cli::HandArgs args;
  args.objects = objects;
  args.mode = mode;
  args.spread = spread;
  args.g = g;
  args.g_a = g_a;
  args.g_b = g_b;
  args.g_c = g_c;
  return args;
}

// `hybrid hand --json` (without --simulate): the report as JSON text.
std::string HandJsonText(const std::vector<std::string>& objects, const std::string& mode,
                         std::optional<double> spread, double g, std::optional<double> g_a,
                         std::optional<double> g_b, std::optional<double> g_c, bool joint_state) {
  cli::HandArgs args = HandArgsOf(objects, mode, spread, g, g_a, g_b, g_c);
  args.joint_state = joint_state;
  py::gil_scoped_release release;
  return cli::HandReport(args).dump();
}

// A numpy array of `shape` holding `values` (row-major).
py::array_t<double> ArrayOf(const std::vector<double>& values, std::vector<py::ssize_t> shape) {
  py::array_t<double> out(shape);
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

// The (n, 2) offsets of a sweep as rows.
std::vector<std::array<double, 2>> OffsetRows(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& offsets) {
  if (offsets.ndim() != 2 || offsets.shape(1) != 2) {
    throw cli::OptionError("offsets", cli::Arg("offsets") + " must be an array of shape (n, 2)");
  }
  std::vector<std::array<double, 2>> rows(offsets.shape(0));
  const double* data = offsets.data();
  for (size_t r = 0; r < rows.size(); ++r) rows[r] = {data[2 * r], data[2 * r + 1]};
  return rows;
}

// A grasp sweep as a dict of numpy arrays (numbers) and lists (strings), shaped per row, finger
// and link.
py::dict SweepDict(const cli::GraspSweep& s) {
  const py::ssize_t n = static_cast<py::ssize_t>(s.status.size()), f = s.fingers;
  py::dict out;
  out["status"] = s.status;
  out["message"] = s.message;
  out["first_contact"] = ArrayOf(s.first_contact, {n});
  out["motor"] = ArrayOf(s.motor, {n, f});
  out["theta"] = ArrayOf(s.theta, {n, f, 3});
  out["phase"] = s.phase;
  out["mode"] = s.mode;
  out["contact_g"] = ArrayOf(s.contact_g, {n, f, 3});
  out["contact_by"] = s.contact_by;
  out["stop"] = ArrayOf(s.stop, {n, f});
  return out;
}

py::dict HandSweepDict(
    const std::vector<std::string>& objects,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& offsets,
    const std::string& mode, std::optional<double> spread, double g, std::optional<double> g_a,
    std::optional<double> g_b, std::optional<double> g_c, int threads) {
  const cli::HandArgs args = HandArgsOf(objects, mode, spread, g, g_a, g_b, g_c);
  const std::vector<std::array<double, 2>> rows = OffsetRows(offsets);
  cli::GraspSweep sweep;
  {
    py::gil_scoped_release release;
    sweep = cli::HandSweep(args, rows, threads);
  }
  return SweepDict(sweep);
}

py::dict FingerSweepDict(
    const std::vector<std::string>& objects,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& offsets, double g,
    int threads) {
  const std::vector<std::array<double, 2>> rows = OffsetRows(offsets);
  cli::GraspSweep sweep;
  {
    py::gil_scoped_release release;
    sweep = cli::FingerSweep(objects, g, rows, threads);
  }
  return SweepDict(sweep);
}

// `hybrid finger --g G [--gob1..3] [--object ...] --json`: the report as JSON text.
std::string FingerJsonText(double g, std::optional<double> gob1, std::optional<double> gob2,
                           std::optional<double> gob3, const std::vector<std::string>& objects) {
  cli::FingerArgs args;
  args.g = g;
  args.gob = {gob1, gob2, gob3};
  args.objects = objects;
  py::gil_scoped_release release;
  return cli::FingerReportJson(args).dump();
}

// hybrid.Gripper: the stateful emulator (include/hybrid/gripper/gripper_emulator.h) with registers
// as a dict of names and the state as a dict.
class Gripper {
 public:
  Gripper(const std::optional<std::string>& model, const std::vector<std::string>& objects)
      : emulator_(
            spaceex::ReadModelFile(model ? *model : cli::BundledFile("spec/gripper.ha").string()),
            cli::ParseObjectList(objects)) {}

  // Writes the registers named in `values` (the others keep their values).
  void Command(const std::map<std::string, int>& values) {
    gripper::GripperRegisters r = emulator_.registers();
    for (const auto& [name, value] : values) {
      int* field = r.Find(name);
      if (field == nullptr) {
        throw cli::OptionError("registers", cli::Arg("registers") + ": no register named '" + name +
                                                "' (rACT, rMOD, rGTO, rATR, rGLV, rICF, "
                                                "rICS, rPRA..rPRS, rSPA..rSPS, rFRA..rFRS)");
      }
      *field = value;
    }
    emulator_.Command(r);
  }

  py::dict Step(double dt) {
    {
      py::gil_scoped_release release;
      emulator_.Step(dt);
    }
    return State();
  }

  py::dict State() const {
    const gripper::GripperState& st = emulator_.state();
    const gripper::GripperStatus& g = st.status;
    py::dict status;
    for (const auto& [name, value] : {std::pair{"gACT", g.gACT},
                                      {"gMOD", g.gMOD},
                                      {"gGTO", g.gGTO},
                                      {"gIMC", g.gIMC},
                                      {"gSTA", g.gSTA},
                                      {"gFLT", g.gFLT}}) {
      status[name] = value;
    }
    const std::string axes = "ABCS";
    for (int k = 0; k < 4; ++k) {
      status[("gDT" + std::string(1, axes[k])).c_str()] = g.gDT[k];
      status[("gPR" + std::string(1, axes[k])).c_str()] = g.gPR[k];
      status[("gPO" + std::string(1, axes[k])).c_str()] = g.gPO[k];
      status[("gCU" + std::string(1, axes[k])).c_str()] = g.gCU[k];
    }
    py::array_t<double> theta({3, 3});
    for (int f = 0; f < 3; ++f) {
      for (int i = 0; i < 3; ++i) theta.mutable_at(f, i) = st.theta[f][i];
    }
    py::dict joints;
    joints["name"] = st.joints.name;
    joints["position"] = st.joints.position;
    joints["model_position"] = st.joints.model_position;
    joints["clamped"] = st.joints.clamped;
    py::dict out;
    out["time"] = st.time;
    out["status"] = status;
    out["theta"] = theta;
    out["motor"] = std::vector<double>(st.motor.begin(), st.motor.end());
    out["scissor"] = st.scissor;
    out["spread_angle"] = st.spread_angle;
    out["joint_state"] = joints;
    out["simulation"] = st.simulation;
    out["message"] = st.message;
    return out;
  }

 private:
  gripper::GripperEmulator emulator_;
};

// `hybrid diagnose DATA --json`: the report as JSON text (the bundled finger without a model).
std::string DiagnoseJsonText(const std::string& data, const std::optional<std::string>& model,
                             double significance, int threads) {
  cli::DiagnoseArgs args;
  args.data = data;
  args.model = model ? *model : cli::BundledFile("spec/finger.ha").string();
  args.significance = significance;
  args.threads = threads;
  return RunStoppable([&] { return cli::DiagnoseReport(args).dump(); });
}

// `hybrid diagnose MODEL DATA --json` (a trace of any model) with the curves, as JSON text.
std::string DiagnoseModelJsonText(const std::string& model, const std::string& data,
                                  double significance, int threads,
                                  const std::vector<std::string>& noise) {
  cli::DiagnoseModelArgs args;
  args.model = model;
  args.data = data;
  args.significance = significance;
  args.threads = threads;
  args.noise = noise;
  return RunStoppable([&] { return cli::DiagnoseModelReport(args, true).dump(); });
}

// set_log_level: the engines' log (include/hybrid/automaton/log.h) on standard error from `level`
// ("debug", "info" or "warning") up, or none (None). Standard error rather than Python's logging:
// engines log from worker threads and from the child processes of RunStoppable, where Python
// cannot be called.
void SetLogLevel(const std::optional<std::string>& level) {
  if (!level) {
    SetLogSink({});
    return;
  }
  LogLevel minimum;
  if (!ParseLogLevel(*level, &minimum)) {
    throw cli::OptionError(
        "level",
        cli::Arg("level") + " must be 'debug', 'info', 'warning' or None, not '" + *level + "'");
  }
  SetLogSink(StderrLogSink(), minimum);
}

// Sets the Python error for an OptionError: a ValueError whose message names the keyword
// argument and whose attribute `argument` is its name.
void RaiseOptionError(const cli::OptionError& e) {
  py::object error = py::handle(PyExc_ValueError)(e.what());
  error.attr("argument") = e.argument();
  PyErr_SetObject(PyExc_ValueError, error.ptr());
}

}  // namespace
}  // namespace hybrid::python

PYBIND11_MODULE(_hybrid, m) {
  using namespace hybrid::python;
  m.doc() = "C++ core of the hybrid package (see the package docstrings; docs/python.md).";
  static py::exception<hybrid::ParseError> model_error(m, "ModelError", PyExc_ValueError);
  static py::exception<hybrid::DataError> data_error(m, "DataError", PyExc_ValueError);
  // Errors in Python's words: the commands' messages refer to arguments by their API names, which
  // are the keyword arguments (what() renders them so).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const hybrid::ParseError& e) {
      model_error(e.what());
    } catch (const hybrid::DataError& e) {
      data_error(e.what());
    } catch (const hybrid::cli::OptionError& e) {
      RaiseOptionError(e);
    } catch (const hybrid::cli::OutputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const hybrid::cli::CommandError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const hybrid::InternalError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::out_of_range& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.def("set_log_level", &SetLogLevel, py::arg("level"));
  m.def("finger_angles_one", &FingerAnglesOne, py::arg("g"), py::arg("gob1"), py::arg("gob2"),
        py::arg("gob3"));
  m.def("finger_angles", &FingerAngles, py::arg("g"), py::arg("gob1") = py::none(),
        py::arg("gob2") = py::none(), py::arg("gob3") = py::none(), py::arg("model") = py::none(),
        py::arg("out") = py::none());
  m.def("hand_sweep", &HandSweepDict, py::arg("objects"), py::arg("offsets"), py::arg("mode"),
        py::arg("spread"), py::arg("g"), py::arg("g_a"), py::arg("g_b"), py::arg("g_c"),
        py::arg("threads"));
  m.def("finger_sweep", &FingerSweepDict, py::arg("objects"), py::arg("offsets"), py::arg("g"),
        py::arg("threads"));
  m.def("finger_json", &FingerJsonText, py::arg("g"), py::arg("gob1"), py::arg("gob2"),
        py::arg("gob3"), py::arg("objects"));
  m.def("hand_json", &HandJsonText, py::arg("objects"), py::arg("mode"), py::arg("spread"),
        py::arg("g"), py::arg("g_a"), py::arg("g_b"), py::arg("g_c"),
        py::arg("joint_state") = false);
  m.def("diagnose_json", &DiagnoseJsonText, py::arg("data"), py::arg("model"),
        py::arg("significance"), py::arg("threads"));
  m.def("diagnose_model_json", &DiagnoseModelJsonText, py::arg("model"), py::arg("data"),
        py::arg("significance"), py::arg("threads"), py::arg("noise"));
  m.def("is_trace_file", &hybrid::IsTraceFile, py::arg("path"));
  py::class_<Gripper>(m, "Gripper")
      .def(py::init<std::optional<std::string>, std::vector<std::string>>(), py::arg("model"),
           py::arg("objects"))
      .def("command", &Gripper::Command, py::arg("registers"))
      .def("step", &Gripper::Step, py::arg("dt"))
      .def("state", &Gripper::State);
  py::class_<Model>(m, "Model")
      .def(py::init<std::string, std::optional<std::string>>(), py::arg("path"),
           py::arg("config") = py::none())
      .def_property_readonly("path", &Model::path)
      .def_property_readonly("name", &Model::name)
      .def("info_json", &Model::InfoJsonText)
      .def("dot", &Model::Dot, py::arg("product") = false)
      .def("check_json", &Model::CheckJsonText, py::arg("properties"), py::arg("method"),
           py::arg("budget"), py::arg("depth"))
      .def("reach_set", &Model::ReachSet, py::arg("properties"), py::arg("budget"),
           py::arg("order"), py::arg("step"))
      .def("simulate", &Model::Simulate, py::arg("until") = py::none(),
           py::arg("inputs") = std::map<std::string, SignalValue>{}, py::arg("sample") = py::none(),
           py::arg("parameters") = std::map<std::string, double>{},
           py::arg("init") = std::map<std::string, double>{}, py::arg("tolerance") = py::none());
}
