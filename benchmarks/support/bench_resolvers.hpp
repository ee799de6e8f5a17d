#pragma once
/// \file
/// The resolvers the benchmark families compare, by row name: "ledas" (complementary mode),
/// "ledas_paper" (the paper's rounds) and "mirtich" (sequential). One place, so `resolve`, `step` and
/// `peers` run them with identical settings.

#include "impetus/resolution/ledas/ledas.hpp"
#include "impetus/resolution/mirtich/mirtich.hpp"

#include <memory>
#include <string>

namespace impetus::bench {

/// `velocity_only` switches the position correction off (correction = 0): the paper's measurement.
inline std::unique_ptr<CollisionResolver> make_resolver(const std::string& name, bool velocity_only) {
  if (name == "mirtich") {
    MirtichSettings s;
    if (velocity_only) s.resting.correction = 0.0;
    return std::make_unique<MirtichResolver>(s);
  }
  LedasSettings s;
  s.mode = name == "ledas_paper" ? LedasMode::paper : LedasMode::complementary;
  // The paper mode needs ~10 N² rounds on the line with e = 0 (101 559 for N = 100): the benchmarks cap
  // it at 2·10⁵ rounds per island so the large rows end in seconds and show non_converged instead.
  if (s.mode == LedasMode::paper) s.max_rounds = 200000;
  if (velocity_only) s.resting.correction = 0.0;
  // Each timed iteration solves the same problem again: a warm start from the previous iteration's
  // answer would time a lookup of the answer, so the frictional solve starts cold every time.
  if (velocity_only) s.warm_start = false;
  return std::make_unique<LedasResolver>(s);
}

}  // namespace impetus::bench
