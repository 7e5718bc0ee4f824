// Strang splitting on the direct problem y' = L y + N(y), with the exact flow of each part:
//     y^{n+1} = e^{hL/2} Phi^N_{t_n -> t_n + h} e^{hL/2} y^n.
// Second order and time-symmetric; the classical reference for NLS (the paper's) and the
// baseline a user would pick when the model's nonlinear part has an exact flow.
#include <memory>

#include "tsi/plugin.hpp"

namespace {

using tsi::Vector;

class Strang final : public tsi::Stepper {
 public:
  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    problem.linear_flow(0.5 * h, y);
    problem.nonlinear_flow(t, h, y);
    problem.linear_flow(0.5 * h, y);
  }
};

void register_strang(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "strang";
  entry.info.aliases = {"strang-splitting"};
  entry.info.summary =
      "Strang splitting with the exact linear and nonlinear flows (direct problem; models with "
      "an exact nonlinear flow: nls, cpd)";
  entry.traits.order = 2;
  entry.traits.symmetric = true;
  entry.traits.needs_exact_flows = true;  // refused at configuration time without them
  entry.traits.reformulations = {"direct"};
  entry.create = [](const tsi::Params&) { return std::make_unique<Strang>(); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("strang", register_strang)
