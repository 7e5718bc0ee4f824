#pragma once
#include <cstddef>
#include <istream>
#include <string>
#include <vector>

#include "tsi/params.hpp"
#include "tsi/registry.hpp"
#include "tsi/resolved_selection.hpp"

namespace tsi::app {

/// The most times output.times may list.
inline constexpr std::size_t max_output_times = 100000;
/// reference.scheme's value that asks for the model's exact solution instead of a solver.
inline constexpr const char* exact_reference = "exact";

/// Parses JSON strictly: a duplicated key, nesting deeper than 64 levels or a number beyond a
/// double is a ConfigError naming where (`origin`, then the key path).
Json parse_json(std::istream& in, const std::string& origin);

/// Reads a JSON config file; a missing or malformed file is a ConfigError naming it.
Json load_config_file(const std::string& path);

/// Sets `value` at a dotted config path, creating objects on the way. The first component
/// must be a known section; `origin` names where the assignment came from in errors.
void assign_path(Json& config, const std::string& path, const Json& value, const std::string& origin);

/// Applies one `--set key.path=value` (value parsed as JSON, else taken as a string).
/// A path through a non-object, or an unknown section, is a ConfigError naming the path.
void apply_override(Json& config, const std::string& assignment);

/// The model parameters that may name a file: u0 (a .npy state) and particles (a particle
/// model's initial particles).
inline constexpr const char* model_file_keys[] = {"u0", "particles"};

/// Makes a file a run config names relative to the config file absolute: model.u0 and
/// model.particles as file names, relative to the directory of `config_path` (the run config,
/// or the study whose base, cases or lists it comes from), as the config's plugins are. An
/// absolute name, a value that is not a string, or a config without them are left as they are.
void resolve_config_files(Json& raw, const std::string& config_path);

/// Validates a run config against the registry and fills every default: the result names
/// every parameter that the run uses (canonical names, model's n_tau, scheme's data order).
Json resolve_run_config(const Json& raw, const Registry& registry);

/// The model, reformulation and scheme of a resolved run config, as the core's assembler takes
/// them (tsi::assemble).
ResolvedSelection resolved_selection(const Json& resolved);

/// A top-level section of a run config, as `tsi list config` shows it: the runner's own
/// sections carry their parameter schema; model, reformulation and scheme name a registered
/// entry (`chosen_from`) whose parameters come with it; plugins is a list of files.
struct RunnerSection {
  std::string name;
  std::string summary;
  const ParamSchema* params = nullptr;  ///< the runner's own sections (time, reference, output, monitor)
  std::string chosen_from;              ///< the registry kind its "name" names, or empty
};

/// Every top-level section of a run config, in the order `tsi list config` shows them.
std::vector<RunnerSection> runner_sections();

/// Number of steps t_end / h (t_end must be a whole number of steps).
long step_count(const Json& resolved);

/// The section of an object config without its "name" key.
Json without_name(const Json& section);

}  // namespace tsi::app
