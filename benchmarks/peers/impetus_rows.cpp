// Impetus's own resolvers in the peers table, run exactly as benchmarks/resolve.cpp runs them: the resolver
// alone on the prepared contact list (detection done once, outside the timed step), position correction
// off, velocities restored before every step.
#include "peers.hpp"

#include "support/bench_resolvers.hpp"

namespace impetus::peers {
namespace {


class ImpetusStep final : public PeerStep {
 public:
  ImpetusStep(const bench::PreparedScene& scene, const std::string& resolver)
      : scene_(scene), bodies_(scene.bodies), contacts_(scene.contacts), resolver_(bench::make_resolver(resolver, /*velocity_only=*/true)) {}

  void reset() override {
    bench::restore_velocities(bodies_, scene_.bodies);
    contacts_ = scene_.contacts;
    counters_ = ResolverCounters{};
  }

  void step() override { resolver_->resolve(bodies_, contacts_, {}, StepContext{}, counters_); }

  StepResult result() override {
    StepResult r;
    for (const RigidBody& b : bodies_) {
      r.velocity.push_back(b.velocity);
      r.angular_velocity.push_back(b.angular_velocity);
    }
    for (const Contact& c : contacts_) r.impulses.push_back(c.impulse);
    r.engine_contacts = r.matched = contacts_.size();
    r.iterations = static_cast<double>(counters_.rounds);
    r.failures = static_cast<double>(counters_.non_converged);
    return r;
  }

 private:
  const bench::PreparedScene& scene_;
  std::vector<RigidBody> bodies_;
  std::vector<Contact> contacts_;
  std::unique_ptr<CollisionResolver> resolver_;
  ResolverCounters counters_;
};

}  // namespace

void add_impetus_methods(std::vector<Method>& out) {
  for (const std::string resolver : {"ledas", "ledas_paper", "mirtich"}) {
    Method m;
    m.name = "impetus_" + resolver;
    // The paper's round-by-round mode takes seconds to minutes beyond pyramid 20 (bench_resolve has those).
    if (resolver == "ledas_paper") m.max_bodies = 210;
    m.make = [resolver](const bench::PreparedScene& scene, const StepSettings&) {
      return std::make_unique<ImpetusStep>(scene, resolver);
    };
    out.push_back(std::move(m));
  }
}

}  // namespace impetus::peers
