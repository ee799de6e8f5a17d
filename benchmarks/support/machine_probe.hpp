#pragma once
/// \file
/// What this machine allows two threads, measured beside the dynamic rows (bench_step's `machine/…` rows).
///
/// On the 2-vCPU virtual machine of docs/benchmarks.md the two vCPUs do not run the dynamic scenes
/// alike: the same one-thread steps of the 1,000-primitive pile, pinned to one vCPU then the other, took
/// 4.0–4.3 ms on one and 5.3–5.6 ms on the other (2026-12-07), and which one was slower changed within
/// the hour, while a pure arithmetic loop ran at one speed on both. So a one-thread row runs at the speed
/// of whichever vCPU the system gave it (the drift between runs that docs/benchmarks.md notes), and two
/// threads cannot give a scene twice the speed of the faster one. The probe, `machine/pile_1000_cpu<k>`
/// (step.cpp), is `step/ledas/pile_1000_t1` with its thread pinned to vCPU k (PinnedThread, Linux only),
/// one row per vCPU the process may use. (A microbenchmark did not show it: chains of dependent loads
/// through 4 MiB ran alike on both vCPUs in the same hour, and two at once slowed each other, sharing L3.)

#include <vector>

#ifdef __linux__
#include <sched.h>
#endif

namespace impetus::bench {

/// The calling thread pinned to one vCPU while it lives (Linux; elsewhere, and if the system refuses,
/// `ok()` is false and nothing changed); its mask restored after.
class PinnedThread {
 public:
  explicit PinnedThread(int cpu) {
#ifdef __linux__
    cpu_set_t only;
    CPU_ZERO(&only);
    CPU_SET(cpu, &only);
    ok_ = sched_getaffinity(0, sizeof before_, &before_) == 0 && sched_setaffinity(0, sizeof only, &only) == 0;
#else
    (void)cpu;
#endif
  }
  ~PinnedThread() {
#ifdef __linux__
    if (ok_) sched_setaffinity(0, sizeof before_, &before_);
#endif
  }
  PinnedThread(const PinnedThread&) = delete;
  PinnedThread& operator=(const PinnedThread&) = delete;
  bool ok() const { return ok_; }

 private:
  bool ok_ = false;
#ifdef __linux__
  cpu_set_t before_;
#endif
};

/// The vCPUs this process may run on (Linux; elsewhere none).
inline std::vector<int> allowed_cpus() {
  std::vector<int> cpus;
#ifdef __linux__
  cpu_set_t mask;
  if (sched_getaffinity(0, sizeof mask, &mask) == 0)
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
      if (CPU_ISSET(cpu, &mask)) cpus.push_back(cpu);
#endif
  return cpus;
}

}  // namespace impetus::bench
