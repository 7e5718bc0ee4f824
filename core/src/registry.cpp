#include "tsi/registry.hpp"

#include <algorithm>

#include "tsi/error.hpp"
#include "tsi/time_as_variable.hpp"

namespace tsi {

namespace {

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

/// The entries of one kind, by name, plus the alias -> name map. std::map keeps entries
/// at stable addresses and sorted by name.
template <class Entry>
struct Table {
  std::string kind;    ///< "model", "reformulation", "scheme"
  std::string plural;  ///< "models", ...
  std::map<std::string, Entry> entries;
  std::map<std::string, std::string> aliases;

  /// The entry a name or alias denotes, or nullptr.
  const Entry* find(const std::string& key) const {
    auto it = entries.find(key);
    if (it != entries.end()) return &it->second;
    auto alias = aliases.find(key);
    return alias == aliases.end() ? nullptr : &entries.at(alias->second);
  }

  /// Refuses a name or alias that is already taken, naming who took it.
  void check_free(const std::string& key, const std::string& provider) const {
    const Entry* taken = find(key);
    if (!taken) return;
    const std::string as =
        taken->info.name == key ? "" : " as an alias of " + quoted(taken->info.name);
    throw PluginError(kind + " " + quoted(key) + " is already registered by " +
                      taken->info.provider + as + " (while registering from " + provider + ")");
  }

  void add(Entry entry, const std::string& provider) {
    check_free(entry.info.name, provider);
    for (const auto& alias : entry.info.aliases) check_free(alias, provider);
    entry.info.provider = provider;
    const std::string name = entry.info.name;
    for (const auto& alias : entry.info.aliases) {
      if (alias != name) aliases[alias] = name;
    }
    entries.emplace(name, std::move(entry));
  }

  const Entry& get(const std::string& key, const std::string& field) const {
    if (const Entry* e = find(key)) return *e;
    const std::string unknown = "unknown " + kind + " " + quoted(key) + "; ";
    if (entries.empty()) throw ConfigError(field, unknown + "no " + plural + " are registered");
    std::string list;
    for (const auto& [name, e] : entries) {
      list += (list.empty() ? "" : ", ") + name;
      const auto& a = e.info.aliases;
      if (!a.empty()) list += (a.size() == 1 ? " (alias: " : " (aliases: ") + join(a) + ")";
    }
    // Models and schemes also come from plugins: one that was not loaded is the likely miss.
    const std::string hint = kind == "reformulation" ? ""
                                                     : "; a " + kind + " from a plugin needs the plugin loaded: --plugin "
                                                       "FILE, TSI_PLUGIN_PATH, the config's \"plugins\" list, or "
                                                       "tsi.load_plugin(FILE) in Python" +
                                                       (kind == "field" ? std::string("; a field in Python: tsi.register_field")
                                                                        : std::string());
    throw ConfigError(field, unknown + "valid " + plural + " are: " + list + hint);
  }

  std::vector<const Entry*> sorted() const {
    std::vector<const Entry*> out;
    for (const auto& [name, e] : entries) out.push_back(&e);
    return out;
  }

  void remove_provider(const std::string& provider) {
    std::erase_if(entries, [&](const auto& kv) { return kv.second.info.provider == provider; });
    std::erase_if(aliases, [&](const auto& kv) { return !entries.contains(kv.second); });
  }
};

bool has_param(const ParamSchema& schema, const std::string& name) {
  return std::any_of(schema.begin(), schema.end(),
                     [&](const ParamSpec& s) { return s.name == name; });
}

}  // namespace

struct Registry::Impl {
  Table<ModelEntry> models{"model", "models", {}, {}};
  Table<ReformulationEntry> reformulations{"reformulation", "reformulations", {}, {}};
  Table<SchemeEntry> schemes{"scheme", "schemes", {}, {}};
  Table<FieldEntry> fields{"field", "fields", {}, {}};
  std::string provider = "core";
};

Registry::Registry() : impl_(std::make_unique<Impl>()) {}
Registry::~Registry() = default;

void Registry::add_model(ModelEntry entry) {
  auto& params = entry.info.params;
  if (!has_param(params, "eps")) {
    params.push_back(
        number_param("eps", 0.01, "the small parameter: stiffness 1/eps of the linear part")
            .check([](const Json& v) { return v.get<double>() >= 1e-300 && v.get<double>() <= 1.0; },
                   "a number in (0, 1], at least 1e-300 (1/eps must be a finite double)"));
  }
  if (!has_param(params, "u0")) {
    params.push_back(
        array_param("u0", "initial value in physical variables; default: the model's own")
            .check([](const Json&) { return true; },
                   "an array of numbers (complex ones as [re, im]) or the name of a .npy file"));
  }
  // A model with a time-dependent f is created carrying t (time_as_variable.hpp): whoever
  // creates it (a run, `tsi check`, Python) gets the model every scheme integrates.
  if (entry.create)
    entry.create = [create = std::move(entry.create)](const Params& p) { return with_time_as_variable(create(p)); };
  impl_->models.add(std::move(entry), impl_->provider);
}

void Registry::add_reformulation(ReformulationEntry entry) {
  impl_->reformulations.add(std::move(entry), impl_->provider);
}

void Registry::add_scheme(SchemeEntry entry) {
  impl_->schemes.add(std::move(entry), impl_->provider);
}

void Registry::add_field(FieldEntry entry) {
  if (!entry.create) throw PluginError("field \"" + entry.info.name + "\" has no create function");
  impl_->fields.add(std::move(entry), impl_->provider);
}

const ModelEntry& Registry::model(const std::string& name, const std::string& field) const {
  return impl_->models.get(name, field);
}

const ReformulationEntry& Registry::reformulation(const std::string& name,
                                                  const std::string& field) const {
  return impl_->reformulations.get(name, field);
}

const SchemeEntry& Registry::scheme(const std::string& name, const std::string& field) const {
  return impl_->schemes.get(name, field);
}

std::vector<const ModelEntry*> Registry::models() const { return impl_->models.sorted(); }

std::vector<const ReformulationEntry*> Registry::reformulations() const {
  return impl_->reformulations.sorted();
}

std::vector<const SchemeEntry*> Registry::schemes() const { return impl_->schemes.sorted(); }

std::vector<const FieldEntry*> Registry::fields() const { return impl_->fields.sorted(); }

const FieldEntry& Registry::field(const std::string& name, const std::string& path) const {
  return impl_->fields.get(name, path);
}

void Registry::check_compatible(const SchemeEntry& scheme,
                                const ReformulationEntry& reformulation) const {
  auto names = scheme.traits.reformulations;
  const auto supports = [&names](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  const auto& info = reformulation.info;
  if (supports(info.name) || std::any_of(info.aliases.begin(), info.aliases.end(), supports))
    return;
  std::sort(names.begin(), names.end());
  throw ConfigError(
      "reformulation.name",
      "scheme " + quoted(scheme.info.name) + " cannot integrate the " + quoted(info.name) +
          " reformulation; compatible reformulations: " + (names.empty() ? "none" : join(names)));
}

void Registry::set_provider(std::string provider) { impl_->provider = std::move(provider); }

const std::string& Registry::provider() const { return impl_->provider; }

void Registry::remove_provider(const std::string& provider) {
  impl_->models.remove_provider(provider);
  impl_->reformulations.remove_provider(provider);
  impl_->schemes.remove_provider(provider);
  impl_->fields.remove_provider(provider);
}

}  // namespace tsi

namespace tsi {

StepperTraits scheme_traits(const SchemeEntry& scheme, const Json& params) {
  return scheme.traits_for ? scheme.traits_for(params) : scheme.traits;
}

StepperTraits default_traits(const SchemeEntry& scheme) {
  return scheme_traits(scheme, resolve_params(scheme.info.params, Json::object(), "scheme"));
}

}  // namespace tsi
