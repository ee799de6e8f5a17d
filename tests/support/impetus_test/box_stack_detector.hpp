#pragma once
// A detector for box stacks without FCL, shared by the resolver tests: exact for boxes stacked nearly
// axis-aligned on the ground.

#include "impetus/conformance/fixtures.hpp"
#include "impetus/modules/detector.hpp"

#include <span>
#include <variant>
#include <vector>

namespace impetus::test {

/// Contacts of boxes on a ground plane z = 0 (body 0) and of box j on box j − 1 (a stack, nearly
/// axis-aligned): each corner of the upper box within `margin` of the lower face and above it.
class BoxStackDetector final : public CollisionDetector {
 public:
  explicit BoxStackDetector(double margin) : margin_(margin) {}
  ModuleStatus set_bodies(std::span<const RigidBody>, std::span<const BodyPair>) noexcept override { return {}; }
  void detect(std::span<const RigidBody> bodies, const StepContext&, std::vector<Contact>& contacts,
              DetectorCounters& counters) noexcept override {
    for (BodyIndex j = 1; j < bodies.size(); ++j) {
      const RigidBody& upper = bodies[j];
      const Vec3 half_u = 0.5 * std::get<Box>(upper.shape).size;
      const RigidBody& lower = bodies[j - 1];
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 local((corner & 1 ? 1 : -1) * half_u.x(), (corner & 2 ? 1 : -1) * half_u.y(),
                         (corner & 4 ? 1 : -1) * half_u.z());
        const Vec3 p = upper.position + upper.rotation * local;
        if (j == 1) {  // on the ground
          if (p.z() < margin_) contacts.push_back(conformance::contact(0, j, p, Vec3::UnitZ(), -p.z()));
          continue;
        }
        const Vec3 half_l = 0.5 * std::get<Box>(lower.shape).size;
        const Vec3 in_lower = lower.rotation.transpose() * (p - lower.position);
        const double height = in_lower.z() - half_l.z();
        if (height < margin_ && height > -half_l.z() && std::abs(in_lower.x()) <= half_l.x() + 1e-9 &&
            std::abs(in_lower.y()) <= half_l.y() + 1e-9)
          contacts.push_back(conformance::contact(j - 1, j, p, lower.rotation.col(2), -height));
      }
    }
    counters.contacts += contacts.size();
  }

 private:
  double margin_;
};

}  // namespace impetus::test
