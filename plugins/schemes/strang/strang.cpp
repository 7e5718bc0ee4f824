// Strang splitting on the direct problem y' = L y + N(y), with the exact flow of each part:
//     y^{n+1} = e^{hL/2} Phi^N_{t_n -> t_n + h} e^{hL/2} y^n.
// Second order and time-symmetric; the classical reference for NLS (the paper's) and the
// baseline a user would pick when the model's nonlinear part has an exact flow.
#include <memory>
#include <variant>

#include "tsi/plugin.hpp"

namespace {

using tsi::Real;
using tsi::Vector;

class Strang final : public tsi::Stepper {
 public:
  Strang(tsi::Problem& problem, Real h, std::monostate) : Stepper(problem, h) {}

  void step(Real t, Vector& y) override {
    problem_.linear_flow(0.5 * h_, y);
    problem_.nonlinear_flow(t, h_, y);
    problem_.linear_flow(0.5 * h_, y);
  }

  double state_vectors() const override { return 0.0; }
  static double state_vectors_for(const tsi::ProblemLayout&, std::monostate) { return 0.0; }
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
  entry.create = [](const tsi::Params&) { return tsi::make_scheme<Strang>(std::monostate{}); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("strang", register_strang)
