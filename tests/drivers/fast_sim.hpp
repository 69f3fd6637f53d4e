#pragma once
// The simulators as the driver tests run them: 40 times faster than real time (wire and
// latency included), with the given faults.
#include "sim/device.hpp"

namespace testjob {

template <class Config>
Config fast_sim(stipplot::sim::Faults f = {}) {
  Config c;
  c.speedup = 40;
  c.faults = f;
  return c;
}

}  // namespace testjob
