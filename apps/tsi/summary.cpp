#include "summary.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "config.hpp"

namespace tsi::app {

namespace {

// States up to this many values are printed whole at the end of a run's summary.
constexpr Index max_printed_values = 8;

// The first `count` values of x, each in the fewest digits that read back to the same double (complex:
// re+imj, as Python and NumPy print them).
std::string printed_state(const Vector& x, bool complex_state, Index count) {
  std::string out = "[";
  for (Index i = 0; i < std::min(count, x.size()); ++i) {
    if (i > 0) out += ", ";
    out += complex_state ? fmt::format("{}{:+}j", x(i).real(), x(i).imag()) : fmt::format("{}", x(i).real());
  }
  return out + "]";
}

}  // namespace

std::string run_summary(const RunOutcome& outcome, const std::string& out_dir) {
  const Json& r = outcome.result;
  const Json& c = r["config"];
  std::string s;
  s += fmt::format("tsi {}  {} (eps = {:g})  scheme {} on {}\n", r["tsi_version"].get<std::string>(),
                   c["model"]["name"].get<std::string>(), c["model"]["eps"].get<double>(),
                   c["scheme"]["name"].get<std::string>(), c["reformulation"]["name"].get<std::string>());
  s += fmt::format("  h = {:g}, t_end = {:g}, steps = {}\n", c["time"]["h"].get<double>(),
                   c["time"]["t_end"].get<double>(), r.value("steps", 0L));
  if (!outcome.ok) s += fmt::format("  {}: {}\n", r["status"].get<std::string>(), outcome.message);
  if (r.contains("invariants")) {
    if (r.contains("t_reached") && !outcome.ok)
      s += fmt::format("  reached t = {:g} after {} steps\n", r["t_reached"].get<double>(), r["steps"].get<long>());
    for (const char* name : {"H", "I", "m"})  // absent for a model without Hamiltonian structure
      if (r["invariants"].contains(name))
        s += fmt::format("  max rel. change of {}     {:.3e}   ({:.10g} -> {:.10g})\n", name,
                       r["invariants"][name]["max_rel_error"].get<double>(),
                       r["invariants"][name]["initial"].get<double>(), r["invariants"][name]["final"].get<double>());
    for (const auto& [name, inv] : r["invariants"].items())  // the model's own (those with a "change")
      if (inv.contains("change"))
        s += fmt::format("  {:<24} {:.3e}   ({:.10g} -> {:.10g})\n",
                         fmt::format("max {} change of {}", inv["change"] == "relative" ? "rel." : "abs.", name),
                         inv["max_change"].get<double>(), inv["initial"].get<double>(), inv["final"].get<double>());
    for (const auto& [name, inv] : r["invariants"].items())  // the model's diagnostics (not conserved)
      if (inv.contains("conserved") && inv["conserved"] == false)
        s += fmt::format("  {:<24} {:.6g} .. {:.6g}   ({:.10g} -> {:.10g})\n", fmt::format("range of {}", name),
                         inv["min"].get<double>(), inv["max"].get<double>(), inv["initial"].get<double>(),
                         inv["final"].get<double>());
    const Json& sv = r["solver"];
    if (sv["stages"].get<long>() > 0)
      s += fmt::format("  fixed-point sweeps/stage  {:.2f} mean, {} max, {} not converged\n",
                       sv["iterations_mean"].get<double>(), sv["iterations_max"].get<long>(),
                       sv["not_converged"].get<long>());
    s += fmt::format("  nonlinearity evaluations  {}\n", r["rhs_evaluations"].get<long>());
    s += fmt::format("  wall time                 {:.3f} s\n", r["wall_seconds"].get<double>());
  }
  for (const auto& w : r["warnings"]) s += fmt::format("  warning: {}\n", w.get<std::string>());
  // The answer last, where a user looks for it: u at the end (round-trip digits) and its error.
  if (outcome.u_final.size() == 0 && outcome.u_final_written > 0) {  // a split run's, written by every process
    s += fmt::format("  u({}) = {} ... ({} values: {}/{})\n", outcome.ok ? "t_end" : "t_reached",
                     printed_state(outcome.u_final_head, outcome.complex_state, 4), outcome.u_final_written, out_dir,
                     u_final_file);
  }
  if (outcome.u_final.size() > 0) {
    const bool whole = outcome.u_final.size() <= max_printed_values;
    const std::string at = outcome.ok || !r.contains("t_reached")
                               ? std::string("t_end")
                               : fmt::format("t = {:g}", r["t_reached"].get<double>());
    s += whole ? fmt::format("  u({}) = {}\n", at, printed_state(outcome.u_final, outcome.complex_state, max_printed_values))
               : fmt::format("  u({}) = {} ... ({} values: {}/{})\n", at,
                             printed_state(outcome.u_final, outcome.complex_state, 4), outcome.u_final.size(), out_dir,
                             u_final_file);
  }
  if (r.contains("error") && r["error"]["reference"]["scheme"] == exact_reference)
    s += fmt::format("  relative error at t_end   {:.3e}   (reference: the model's exact solution)\n",
                     r["error"]["relative"].get<double>());
  else if (r.contains("error"))
    s += fmt::format("  relative error at t_end   {:.3e}   (reference {} on {}, tol {:g})\n",
                     r["error"]["relative"].get<double>(), r["error"]["reference"]["scheme"].get<std::string>(),
                     r["error"]["reference"]["reformulation"].get<std::string>(),
                     r["error"]["reference"]["tol"].get<double>());
  if (r.contains("error_estimate")) {
    const Json& e = r["error_estimate"];
    if (e["relative"].is_number())
      s += fmt::format("  estimated error (Richardson) {:.3e}   (observed order {} from 2 h, h, h / 2: {})\n",
                       e["relative"].get<double>(),
                       e["observed_order"].is_number() ? fmt::format("{:.2f}", e["observed_order"].get<double>()) : "-",
                       e["asymptotic"].get<bool>() ? "asymptotic" : "NOT asymptotic, unreliable");
    else
      s += fmt::format("  estimated error (Richardson): none, {}\n", e.value("message", std::string("failed")));
  }
  s += fmt::format("  written: {0}/result.json, {0}/invariants.csv", out_dir);
  if (outcome.u_final.size() > 0 || outcome.u_final_written > 0) s += fmt::format(", {}/{}", out_dir, u_final_file);
  if (outcome.reference_u_final.size() > 0 || outcome.reference_written > 0)
    s += fmt::format(", {}/{}", out_dir, reference_u_final_file);
  if (!outcome.u_times.empty() && outcome.u_final.size() > 0) s += fmt::format(", {}/{}", out_dir, u_times_file);
  if (r.contains("fields"))
    s += fmt::format(", {0}/fields.h5 and {0}/fields.xmf ({1} snapshots)", out_dir, r["fields"]["snapshots"].get<long>());
  s += "\n";
  return s;
}

}  // namespace tsi::app
