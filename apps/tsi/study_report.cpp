#include "study_report.hpp"

#include <fmt/format.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "run_files.hpp"
#include "tsi/error.hpp"
#include "tsi/convergence.hpp"
#include "tsi/output.hpp"
#include "tsi/version.hpp"

namespace tsi::app {
namespace {

// The columns of table.csv, before the varied paths that are not among them.
const std::vector<std::string> columns = {
    "id", "label", "model", "scheme", "reformulation", "eps", "h", "t_end", "n_tau", "error", "order",
    "error_estimate", "estimate_ratio", "estimate_asymptotic",
    "err_H", "err_I", "err_m", "drift_H", "drift_I", "drift_m", "sweeps_mean", "rhs_evals",
    "wall_seconds", "t_reached", "status"};
const std::set<std::string> covered = {"model.name", "scheme.name", "reformulation.name", "model.eps",
                                       "time.h", "time.t_end", "reformulation.n_tau"};

Json number_or_null(const Json& j, const Json::json_pointer& p) { return j.contains(p) ? j.at(p) : Json(); }

// The change columns of the invariants the models declare (err_<name>, abs_err_<name>; see
// RunRecorder), as the rows carry them, in order of appearance.
std::vector<std::string> invariant_columns(const Json& rows) {
  std::vector<std::string> out;
  for (const auto& row : rows)
    for (const auto& [key, value] : row.items())
      if ((key.rfind("err_", 0) == 0 || key.rfind("abs_err_", 0) == 0) &&
          std::find(columns.begin(), columns.end(), key) == columns.end() &&
          std::find(out.begin(), out.end(), key) == out.end())
        out.push_back(key);
  return out;
}

// Everything that makes a series: a run's row without its h and the measured values.
std::string series_key(const Json& row, bool without_eps) {
  Json key = {row["label"], row["model"], row["scheme"], row["reformulation"], row["t_end"], row["n_tau"],
              row["varied"]};
  if (!without_eps) key.push_back(row["eps"]);
  return key.dump();
}

std::string fraction(double x) {
  const double inverse = 1.0 / x;
  if (x < 1.0 && std::abs(inverse - std::round(inverse)) < 1e-9 * inverse) return fmt::format("1/{:.0f}", inverse);
  return fmt::format("{:g}", x);
}

std::string cell(const Json& v, const char* format = "{:.3e}") {
  return v.is_number() ? fmt::format(fmt::runtime(format), v.get<double>()) : std::string("-");
}

// A work_at_error entry's time for target k: "<=" marks a bound from the cheapest run.
std::string work_cell(const Json& entry, size_t k) {
  const bool bound = entry["how"][k] == "at_most";
  return (bound ? "<= " : "") + cell(entry["seconds"][k], "{:.2e} s");
}

std::string csv_field(const Json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) {
    std::string s = v.get<std::string>();
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string quoted = "\"";
    for (char c : s) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
    return quoted + "\"";
  }
  if (v.is_number_float()) return fmt::format("{:.10g}", v.get<double>());
  return v.dump();
}

Json machine_json() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  struct utsname u {};
  uname(&u);
  std::string cpu;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  return {{"hostname", host}, {"cpu", cpu}, {"cores", std::thread::hardware_concurrency()},
          {"os", std::string(u.sysname) + " " + u.release}};
}

}  // namespace

double drift_slope(const std::string& csv, const std::string& column, double t_from) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::istringstream h(line); std::getline(h, line, ',');) header.push_back(line);
  const auto it = std::find(header.begin(), header.end(), column);
  if (it == header.end()) return std::nan("");
  const size_t col = static_cast<size_t>(it - header.begin());
  std::vector<double> t, y;
  while (std::getline(in, line)) {
    std::vector<double> v;
    for (std::istringstream fields(line); std::getline(fields, line, ',');) v.push_back(std::stod(line));
    if (v.size() <= col) continue;
    t.push_back(v[0]), y.push_back(v[col]);
  }
  return drift_fit(t, y, t_from).slope;
}

Json study_rows(const Study& study, const std::vector<RunOutcome>& outcomes) {
  Json rows = Json::array();
  for (size_t i = 0; i < study.runs.size(); ++i) {
    const StudyRun& run = study.runs[i];
    const Json& c = run.config;
    const Json& r = outcomes[i].result;
    const double t_end = c["time"]["t_end"];
    Json row = {{"id", run.id},
                {"label", run.label},
                {"model", c["model"]["name"]},
                {"scheme", c["scheme"]["name"]},
                {"reformulation", c["reformulation"]["name"]},
                {"eps", c["model"]["eps"]},
                {"h", c["time"]["h"]},
                {"t_end", t_end},
                {"n_tau", c["reformulation"].value("n_tau", Json())},
                {"error", number_or_null(r, "/error/relative"_json_pointer)},
                {"order", nullptr},
                {"error_estimate", number_or_null(r, "/error_estimate/relative"_json_pointer)},
                {"estimate_ratio", number_or_null(r, "/error_estimate/ratio_to_error"_json_pointer)},
                {"estimate_asymptotic", number_or_null(r, "/error_estimate/asymptotic"_json_pointer)},
                {"err_H", number_or_null(r, "/invariants/H/max_rel_error"_json_pointer)},
                {"err_I", number_or_null(r, "/invariants/I/max_rel_error"_json_pointer)},
                {"err_m", number_or_null(r, "/invariants/m/max_rel_error"_json_pointer)},
                {"sweeps_mean", number_or_null(r, "/solver/iterations_mean"_json_pointer)},
                {"rhs_evals", number_or_null(r, "/rhs_evaluations"_json_pointer)},
                {"wall_seconds", number_or_null(r, "/wall_seconds"_json_pointer)},
                {"t_reached", number_or_null(r, "/t_reached"_json_pointer)},
                {"status", r.value("status", std::string("failed"))},
                {"message", outcomes[i].message}};
    for (const char* x : {"H", "I", "m"}) {
      // Fitted while the run went (its rows may be on disk only), else from the rows in memory.
      const Json drift = outcomes[i].result.contains("invariants") && outcomes[i].result["invariants"].contains(x)
                             ? outcomes[i].result["invariants"][x].value("drift", Json())
                             : Json();
      const double slope = outcomes[i].csv_file.empty() || !drift.is_number()
                               ? drift_slope(outcomes[i].csv, std::string("err_") + x, 0.1 * t_end)
                               : drift.get<double>();
      row[std::string("drift_") + x] = std::isfinite(slope) ? Json(slope) : Json();
    }
    // The model's own invariants: the largest change, under the name of its column in invariants.csv.
    if (r.contains("invariants"))
      for (const auto& [name, inv] : r["invariants"].items())
        if (inv.contains("column")) row[inv["column"].get<std::string>()] = inv.value("max_change", Json());
    Json varied = Json::object();
    for (const auto& [path, value] : run.assignments.items())
      if (!covered.count(path)) varied[path] = value;
    row["varied"] = varied;
    row["warnings"] = r.value("warnings", Json::array());
    rows.push_back(row);
  }
  // Observed order against the next larger h in the same series.
  std::map<std::string, std::vector<size_t>> series;
  for (size_t i = 0; i < rows.size(); ++i) series[series_key(rows[i], false)].push_back(i);
  for (auto& [key, members] : series) {
    std::sort(members.begin(), members.end(),
              [&](size_t a, size_t b) { return rows[a]["h"].get<double>() > rows[b]["h"].get<double>(); });
    for (size_t k = 1; k < members.size(); ++k) {
      const Json &coarse = rows[members[k - 1]], &fine = rows[members[k]];
      if (!coarse["error"].is_number() || !fine["error"].is_number()) continue;
      const double e0 = coarse["error"], e1 = fine["error"], h0 = coarse["h"], h1 = fine["h"];
      if (e0 > 0 && e1 > 0 && h0 != h1) rows[members[k]]["order"] = std::log(e0 / e1) / std::log(h0 / h1);
    }
  }
  return rows;
}

Json convergence_summary(const Json& rows) {
  // Every run of a series, failed ones included: an order is never fitted across a run that
  // has no error (blow-up, failure) nor over one whose error is 0.
  std::map<std::string, std::vector<const Json*>> series;
  for (const auto& row : rows) series[series_key(row, false)].push_back(&row);
  Json out = {{"series", Json::array()}, {"uniform", Json::array()}};
  for (auto& [key, members] : series) {
    std::sort(members.begin(), members.end(), [](const Json* a, const Json* b) { return (*a)["h"] > (*b)["h"]; });
    std::vector<double> h, e;
    Json errors = Json::array();
    size_t failed = 0;
    for (const Json* m : members) {
      const bool has_error = (*m)["error"].is_number();
      h.push_back((*m)["h"]);
      e.push_back(has_error ? (*m)["error"].get<double>() : std::numeric_limits<double>::quiet_NaN());
      errors.push_back(has_error ? (*m)["error"] : Json());
      failed += has_error ? 0 : 1;
    }
    // What makes the series (series_key reads the same fields), then its errors.
    Json s = {{"label", (*members[0])["label"]},   {"scheme", (*members[0])["scheme"]},
              {"model", (*members[0])["model"]},   {"reformulation", (*members[0])["reformulation"]},
              {"t_end", (*members[0])["t_end"]},   {"n_tau", (*members[0])["n_tau"]},
              {"eps", (*members[0])["eps"]},       {"varied", (*members[0])["varied"]},
              {"h", h},                            {"error", errors}};
    Json successive = Json::array();
    for (size_t k = 0; k + 1 < e.size(); ++k)
      successive.push_back(e[k] > 0 && e[k + 1] > 0 ? Json(std::log(e[k] / e[k + 1]) / std::log(h[k] / h[k + 1]))
                                                    : Json());
    s["successive_orders"] = successive;
    const OrderFit fit = fit_order(h, e, 0.0, 2);
    s["least_squares_order"] = fit.finite && fit.measurable && fit.used == e.size() ? Json(fit.order) : Json();
    if (failed) s["failed_runs"] = failed;
    out["series"].push_back(s);
  }
  // Uniform error: at each h, the largest error over eps, per series without eps.
  std::map<std::string, std::map<double, double>> uniform;
  std::map<std::string, const Json*> first;
  for (const auto& row : rows) {
    const std::string key = series_key(row, true);
    double& worst = uniform[key][row["h"].get<double>()];
    // A failed run (no error) makes the maximum unknown: NaN (null in JSON), never the survivors'.
    worst = row["error"].is_number() && !std::isnan(worst) ? std::max(worst, row["error"].get<double>())
                                                           : std::numeric_limits<double>::quiet_NaN();
    first.emplace(key, &row);
  }
  for (const auto& [key, by_h] : uniform) {
    Json u = {{"label", (*first[key])["label"]}, {"scheme", (*first[key])["scheme"]},
              {"model", (*first[key])["model"]}, {"varied", (*first[key])["varied"]},
              {"h", Json::array()}, {"max_error_over_eps", Json::array()}};
    for (auto it = by_h.rbegin(); it != by_h.rend(); ++it) {
      u["h"].push_back(it->first);
      u["max_error_over_eps"].push_back(std::isnan(it->second) ? Json() : Json(it->second));
    }
    out["uniform"].push_back(u);
  }
  return out;
}

// The errors a work-precision study reports the time to (the high orders reach 1e-10).
const std::vector<double> work_targets = {1e-4, 1e-6, 1e-8, 1e-10};

Json work_at_error(const Json& rows, const std::vector<double>& targets) {
  std::map<std::pair<std::string, double>, std::vector<std::pair<double, double>>> series;  // (error, wall)
  std::vector<std::pair<std::string, double>> order;
  for (const auto& row : rows) {
    if (!row["error"].is_number() || !row["wall_seconds"].is_number() || row["error"].get<double>() <= 0) continue;
    const std::string name = row["label"].get<std::string>().empty() ? row["scheme"].get<std::string>()
                                                                     : row["label"].get<std::string>();
    const auto key = std::make_pair(name, row["eps"].get<double>());
    if (!series.count(key)) order.push_back(key);
    series[key].emplace_back(row["error"].get<double>(), std::max(row["wall_seconds"].get<double>(), 1e-9));
  }
  Json out = Json::array();
  for (const auto& key : order) {
    auto points = series[key];
    std::sort(points.begin(), points.end());
    Json seconds = Json::array(), how = Json::array();
    for (double target : targets) {
      Json t, kind;  // null when no run reaches the target
      for (size_t i = 0; i + 1 < points.size(); ++i) {
        const auto [e0, w0] = points[i];
        const auto [e1, w1] = points[i + 1];
        if (e0 <= target && target <= e1) {
          const double x = std::log(target / e0) / std::log(e1 / e0);
          t = std::exp(std::log(w0) + x * std::log(w1 / w0));
          kind = "interpolated";
          break;
        }
      }
      if (t.is_null()) {
        // Every run that reaches the target is below it: the cheapest of them bounds the time.
        for (const auto& [e, w] : points)
          if (e <= target && (t.is_null() || w < t.get<double>())) t = w;
        if (!t.is_null()) kind = "at_most";
      }
      seconds.push_back(t);
      how.push_back(kind);
    }
    out.push_back({{"name", key.first}, {"eps", key.second}, {"targets", targets}, {"seconds", seconds}, {"how", how}});
  }
  return out;
}

std::vector<std::string> write_study_files(const std::string& dir, const Study& study,
                                           const std::vector<RunOutcome>& outcomes, const Json& rows,
                                           double wall_seconds, int jobs) {
  std::vector<std::string> failed;
  for (size_t i = 0; i < study.runs.size(); ++i) {
    try {
      write_run_files(dir + "/runs/" + study.runs[i].id, outcomes[i]);
    } catch (const IoError& e) {
      failed.emplace_back(e.what());
    }
  }
  write_study_table(dir, study, rows, wall_seconds, jobs);
  return failed;
}

void write_study_table(const std::string& dir, const Study& study, const Json& rows, double wall_seconds, int jobs,
                       const Json& execution) {
  std::vector<std::string> extra;
  for (const auto& path : study.varied)
    if (!covered.count(path)) extra.push_back(path);
  const std::vector<std::string> declared = invariant_columns(rows);
  std::string csv;
  for (const auto& c : columns) csv += c + ",";
  for (const auto& c : declared) csv += c + ",";
  for (const auto& p : extra) csv += p + ",";
  csv += "message\n";
  for (const auto& row : rows) {
    for (const auto& c : columns) csv += csv_field(row[c]) + ",";
    for (const auto& c : declared) csv += csv_field(row.value(c, Json())) + ",";
    for (const auto& p : extra) csv += csv_field(row["varied"].value(p, Json())) + ",";
    csv += csv_field(row["message"]) + "\n";
  }
  write_file_atomically(dir + "/table.csv", csv);
  Json out = {{"tsi_version", version_string}, {"study", study.spec}, {"kind", study.kind},
              {"title", study.title}, {"machine", machine_json()}, {"jobs", jobs},
              {"wall_seconds", wall_seconds}, {"table", rows}};
  out["not_used"] = study.not_used;
  for (const auto& [key, value] : execution.items()) out[key] = value;
  if (study.kind == "convergence") out["convergence"] = convergence_summary(rows);
  if (study.kind == "work-precision") out["work_at_error"] = work_at_error(rows, work_targets);
  write_file_atomically(dir + "/study.json", out.dump(2) + "\n");
}

// The Richardson estimates of a convergence table's runs against their true errors (where the
// runs asked for one, output.error_estimate): estimate / error per eps and h, "*" where the
// estimate's own check found the run outside its asymptotic range, and how many of the
// asymptotic ones fall within 0.3x .. 3x.
std::string estimate_table(const std::vector<const Json*>& members, const std::set<double, std::greater<>>& epss,
                           const std::set<double, std::greater<>>& hs) {
  std::map<std::pair<double, double>, const Json*> at;
  bool any = false;
  for (const Json* m : members) {
    at[{(*m)["eps"].get<double>(), (*m)["h"].get<double>()}] = m;
    any = any || !(*m)["estimate_asymptotic"].is_null();
  }
  if (!any) return "";
  std::string s = "  Richardson estimate / true error (* : the estimate found the run pre-asymptotic; - : none)\n";
  int asymptotic = 0, within = 0, pre = 0, missing = 0;
  for (double h : hs) {
    s += fmt::format("  {:>8}", fraction(h));
    for (double e : epss) {
      const auto it = at.find({e, h});
      std::string c;
      if (it != at.end()) {
        const Json& r = *it->second;
        if (r["estimate_ratio"].is_number()) {
          const double ratio = r["estimate_ratio"].get<double>();
          const bool ok = r["estimate_asymptotic"].is_boolean() && r["estimate_asymptotic"].get<bool>();
          c = fmt::format("{:.2f}{}", ratio, ok ? "" : "*");
          if (ok) {
            ++asymptotic;
            within += ratio >= 0.3 && ratio <= 3.0 ? 1 : 0;
          } else {
            ++pre;
          }
        } else {
          c = "-";
          ++missing;
        }
      }
      s += fmt::format("{:>21}", c);
    }
    s += "\n";
  }
  s += fmt::format("  estimate within 0.3x .. 3x of the error: {} of {} asymptotic runs; {} pre-asymptotic (*); {} "
                   "without an estimate or an error\n",
                   within, asymptotic, pre, missing);
  return s;
}

std::string study_text(const Study& study, const Json& rows) {
  std::string s = study.title.empty() ? "" : study.title + "\n";
  for (const auto& [path, ids] : study.not_used.items()) {
    std::string list;
    for (size_t k = 0; k < ids.size() && k < 8; ++k) list += (k ? ", " : "") + ids[k].get<std::string>();
    if (ids.size() > 8) list += fmt::format(", ... ({} runs)", ids.size());
    s += fmt::format("  {} (from the base) is not used by {}: their scheme or model does not take it\n", path, list);
  }
  size_t failed = 0;
  for (const auto& row : rows)
    if (row["status"] != "completed") {
      ++failed;
      s += fmt::format("  {} {} ({}, eps = {:g}, h = {:g}): {}\n", row["status"].get<std::string>(),
                       row["id"].get<std::string>(), row["scheme"].get<std::string>(), row["eps"].get<double>(),
                       row["h"].get<double>(), row["message"].get<std::string>());
    }
  // Warnings of completed runs (tau roughness, coherence, unconverged stages): their first clause.
  for (const auto& row : rows)
    if (row["status"] == "completed")
      for (const auto& w : row.value("warnings", Json::array())) {
        const std::string text = w.get<std::string>();
        s += fmt::format("  warning {} ({}, eps = {:g}, h = {:g}): {}\n", row["id"].get<std::string>(),
                         row["scheme"].get<std::string>(), row["eps"].get<double>(), row["h"].get<double>(),
                         text.substr(0, text.find(':')));
      }
  if (study.kind == "convergence") {
    const Json summary = convergence_summary(rows);
    std::map<std::string, std::vector<const Json*>> groups;  // one table per series without eps
    std::vector<std::string> order;
    std::set<std::string> n_taus;  // several: each table says its own
    for (const auto& row : rows) {
      n_taus.insert(row["n_tau"].dump());
      const std::string key = series_key(row, true);
      if (!groups.count(key)) order.push_back(key);
      groups[key].push_back(&row);
    }
    for (const auto& key : order) {
      const auto& members = groups[key];
      const Json& first = *members[0];
      std::set<double, std::greater<>> epss, hs;
      std::map<std::pair<double, double>, const Json*> at;
      for (const Json* m : members) {
        epss.insert((*m)["eps"].get<double>()), hs.insert((*m)["h"].get<double>());
        at[{(*m)["eps"].get<double>(), (*m)["h"].get<double>()}] = m;
      }
      std::string name = first["label"].get<std::string>().empty() ? first["scheme"].get<std::string>()
                                                                   : first["label"].get<std::string>();
      if (!first["varied"].empty()) name = fmt::format("{} {}", name, first["varied"].dump());
      // (a filtered or direct series has no tau grid of the reformulation: nothing to say)
      if (n_taus.size() > 1 && !first["n_tau"].is_null()) name = fmt::format("{} (n_tau {})", name, first["n_tau"].dump());
      s += fmt::format("\n{} on {}: relative error at t = {:g} (observed order)\n", name,
                       first["model"].get<std::string>(), first["t_end"].get<double>());
      s += fmt::format("  {:>8}", "h");
      for (double e : epss) s += fmt::format("{:>21}", "eps=" + fraction(e));
      s += fmt::format("{:>14}\n", "max over eps");
      for (double h : hs) {
        s += fmt::format("  {:>8}", fraction(h));
        double worst = 0;
        int failed_here = 0;  // a run without an error makes the maximum unknown: never the survivors'
        for (double e : epss) {
          const auto it = at.find({e, h});
          const Json* r = it == at.end() ? nullptr : it->second;
          std::string c = r ? cell((*r)["error"]) : "";
          if (r && (*r)["order"].is_number()) c += fmt::format(" ({:.2f})", (*r)["order"].get<double>());
          if (r && (*r)["error"].is_number()) worst = std::max(worst, (*r)["error"].get<double>());
          if (r && !(*r)["error"].is_number()) ++failed_here;
          s += fmt::format("{:>21}", c);
        }
        s += failed_here ? fmt::format("{:>14}\n", fmt::format("{} failed", failed_here))
                         : fmt::format("{:>14.3e}\n", worst);
      }
      s += fmt::format("  {:>8}", "LS order");
      for (double e : epss) {
        std::string c = "-";
        for (const auto& series : summary["series"])
          if (series["eps"] == e && series_key(series, true) == key) {
            if (series["least_squares_order"].is_number())
              c = fmt::format("{:.2f}", series["least_squares_order"].get<double>());
            else if (series.contains("failed_runs"))  // never fitted across a failure
              c = fmt::format("{} failed", series["failed_runs"].get<size_t>());
          }
        s += fmt::format("{:>21}", c);
      }
      s += "\n";
      s += estimate_table(members, epss, hs);
    }
  } else {
    const bool conservation = study.kind == "conservation";
    // Conservation: a column more per invariant the models declare.
    const std::vector<std::string> declared = conservation ? invariant_columns(rows) : std::vector<std::string>();
    const auto declared_width = [](const std::string& c) {
      return static_cast<int>(std::max<size_t>(11, c.size() + 5));
    };
    // A row's name: its scheme (or label) and what else the study varies, so that rows
    // differing only there can be told apart.
    const auto row_name = [conservation](const Json& row) {
      std::string name = row["label"].get<std::string>().empty() ? row["scheme"].get<std::string>()
                                                                 : row["label"].get<std::string>();
      for (const auto& [path, value] : row["varied"].items())
        if (path != "scheme.tol" || conservation)
          name += fmt::format(" {}={}", path.substr(path.rfind('.') + 1),
                              value.is_string() ? value.get<std::string>() : value.dump());
      return name;
    };
    size_t width = 24;
    for (const auto& row : rows) width = std::max(width, row_name(row).size() + 2);
    s += conservation ? fmt::format("\n  {:<{}}{:>10}{:>11}{:>11}{:>11}{:>11}{:>11}", "scheme", width, "eps", "h", "max err_H",
                                    "drift_H", "max err_I", "max err_m")
                      : fmt::format("\n  {:<{}}{:>10}{:>11}{:>10}{:>11}{:>12}{:>10}\n", "scheme", width, "eps", "h", "tol",
                                    "error", "rhs evals", "wall s");
    if (conservation) {
      for (const auto& c : declared) s += fmt::format("{:>{}}", "max " + c, declared_width(c));
      s += fmt::format("{:>11}  {}\n", "t reached", "status");
    }
    for (const auto& row : rows) {
      const std::string name = row_name(row);
      if (conservation) {
        s += fmt::format("  {:<{}}{:>10}{:>11}{:>11}{:>11}{:>11}{:>11}", name, width, fraction(row["eps"]), fraction(row["h"]),
                         cell(row["err_H"]), cell(row["drift_H"], "{:.2e}"), cell(row["err_I"]), cell(row["err_m"]));
        for (const auto& c : declared) s += fmt::format("{:>{}}", cell(row.value(c, Json())), declared_width(c));
        s += fmt::format("{:>11}  {}\n", cell(row["t_reached"], "{:g}"), row["status"].get<std::string>());
      } else {
        const Json tol = row["varied"].value("scheme.tol", Json());
        s += fmt::format("  {:<{}}{:>10}{:>11}{:>10}{:>11}{:>12}{:>10}\n", name, width, fraction(row["eps"]),
                         fraction(row["h"]), tol.is_number() ? fmt::format("{:.0e}", tol.get<double>()) : "",
                         cell(row["error"]), row["rhs_evals"].is_number() ? row["rhs_evals"].dump() : "-",
                         cell(row["wall_seconds"], "{:.4f}"));
      }
    }
  }
  if (study.kind == "work-precision") {
    const Json work = work_at_error(rows, work_targets);
    s += "\n  wall time to reach a relative error (log-log interpolation between runs; <= : the cheapest run,\n"
         "  when every run is already below the error):\n";
    size_t name_width = 24;  // the longest name and two spaces, so that a long label keeps its columns
    for (const auto& w : work) name_width = std::max(name_width, w["name"].get<std::string>().size() + 2);
    s += fmt::format("  {:<{}}{:>12}", "scheme", name_width, "eps");
    for (const double target : work_targets) s += fmt::format("{:>14}", fmt::format("error {:.0e}", target));
    s += "\n";
    for (const auto& w : work) {
      s += fmt::format("  {:<{}}{:>12}", w["name"].get<std::string>(), name_width, fraction(w["eps"]));
      for (size_t k = 0; k < work_targets.size(); ++k) s += fmt::format("{:>14}", work_cell(w, k));
      s += "\n";
    }
  }
  s += fmt::format("\n  {} runs, {} completed, {} not\n", rows.size(), rows.size() - failed, failed);
  return s;
}

}  // namespace tsi::app
