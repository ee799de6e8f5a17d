// Impetus's own resolvers in the peers table, run exactly as benchmarks/resolve.cpp runs them: the resolver
// alone on the prepared contact list (detection done once, outside the timed step), position correction
// off, velocities restored before every step. And, for the rows under gravity, Impetus's whole step as
// bench_step runs it (momentum integrator, fcl, the resolver with its defaults), timed like an engine's.
#include "peers.hpp"

#include "support/bench_dynamic.hpp"
#include "support/bench_resolvers.hpp"

#include "impetus/engine/world.hpp"
#include "impetus/integrators/momentum/momentum.hpp"

namespace impetus::peers {
namespace {


class ImpetusStep final : public PeerStep {
 public:
  ImpetusStep(const bench::PreparedScene& scene, const std::string& resolver)
      : scene_(scene), bodies_(scene.bodies), contacts_(scene.contacts), resolver_(bench::make_resolver(resolver, /*velocity_only=*/true)) {}

  /// The resolver is made without warm starts (bench::make_resolver): nothing numeric carries over
  /// whatever `carry` says; its symbolic analyses of the (one) contact pattern are kept, as in bench_resolve.
  void reset(std::span<const RigidBody> state, Carry) override {
    bench::restore_state(bodies_, state);
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
    for (const Contact& c : contacts_) {
      r.impulses.push_back(c.impulse);
      r.impulse_vectors.push_back(c.impulse * c.normal + c.tangent_impulse);  // on b
    }
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

/// The momentum integrator, recording the velocities the resolver left (before the positions move). The
/// position stage turns ω with the body, keeping its angular momentum (the gyroscopic term; a sphere's ω
/// does not change), and the resolver's position correction may turn it first; the engines are judged at
/// the velocities their solve left on the snapshot's contacts, so the Impetus row reports these.
class SolvedVelocities final : public Integrator {
 public:
  void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                            IntegratorCounters& counters) noexcept override {
    inner_.integrate_velocities(bodies, ctx, counters);
  }
  void integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                           IntegratorCounters& counters) noexcept override {
    velocity.resize(bodies.size());
    angular_velocity.resize(bodies.size());
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      velocity[i] = bodies[i].velocity;
      angular_velocity[i] = bodies[i].angular_velocity;
    }
    inner_.integrate_positions(bodies, ctx, counters);
  }
  std::vector<Vec3> velocity, angular_velocity;

 private:
  MomentumIntegrator inner_{ModuleOptions{}};
};

/// One whole World::step from the scene's state, the world's own detection included (with
/// SolvedVelocities as its integrator: its copy of the velocities is in the timed step, ~0.1 % of it);
/// the impulses are tallied onto the prepared contacts by pair, as an engine's are.
class ImpetusWholeStep final : public PeerStep {
 public:
  ImpetusWholeStep(const bench::PreparedScene& scene, const StepSettings& settings, const std::string& resolver)
      : scene_(scene), resolver_(resolver), pairs_(scene.contacts), world_(world_settings(settings)) {
    bench::set_up_world(world_, scene.bodies);
    world_.set_integrator(solved_);
    world_.set_resolver(bench::make_resolver(resolver, /*velocity_only=*/false));
  }

  /// Carry::drop: a new resolver, so no warm start and no symbolic analysis survives (the first step of a
  /// new world).
  void reset(std::span<const RigidBody> state, Carry carry) override {
    bench::restore_state(world_.bodies(), state);
    if (carry == Carry::drop) world_.set_resolver(bench::make_resolver(resolver_, /*velocity_only=*/false));
  }
  void step() override { last_ = world_.step(); }

  StepResult result() override {
    StepResult r;
    r.velocity = solved_->velocity;
    r.angular_velocity = solved_->angular_velocity;
    ContactTally tally(pairs_, scene_.contacts, true);
    for (const Contact& c : world_.contacts())
      tally.add(c.a, c.b, c.impulse, c.impulse * c.normal + c.tangent_impulse);  // the whole impulse, on b
    tally.finish(r);
    r.iterations = static_cast<double>(last_.resolver.rounds);
    r.failures = static_cast<double>(last_.resolver.non_converged);
    r.solver_seconds = last_.profile.resolve;
    return r;
  }

 private:
  static WorldSettings world_settings(const StepSettings& s) {
    WorldSettings w;
    w.dt = s.dt;
    w.gravity = s.gravity;
    w.threads = 1;  // per core, as the engines it is compared with
    return w;
  }
  const bench::PreparedScene& scene_;
  std::string resolver_;
  PairIndex pairs_;
  std::shared_ptr<SolvedVelocities> solved_ = std::make_shared<SolvedVelocities>();
  World world_;
  StepStatus last_;
};

}  // namespace

void add_impetus_methods(std::vector<Method>& out) {
  for (const std::string resolver : {"ledas", "ledas_paper", "mirtich"}) {
    Method m;
    m.name = "impetus_" + resolver;
    // The paper's round-by-round mode takes seconds to minutes beyond pyramid 20 (bench_resolve has those).
    if (resolver == "ledas_paper") m.max_bodies = 210;
    m.friction = resolver != "ledas_paper";  // the paper's mode refuses friction
    m.make = [resolver](const bench::PreparedScene& scene, const StepSettings&) {
      return std::make_unique<ImpetusStep>(scene, resolver);
    };
    out.push_back(std::move(m));
    if (resolver == "ledas_paper") continue;
    Method whole;
    whole.name = "impetus_" + resolver + "_step";
    whole.gravity_only = true;
    whole.make = [resolver](const bench::PreparedScene& scene, const StepSettings& settings) {
      return std::make_unique<ImpetusWholeStep>(scene, settings, resolver);
    };
    out.push_back(std::move(whole));
  }
}

}  // namespace impetus::peers
