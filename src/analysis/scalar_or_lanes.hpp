#pragma once
// One-ulp steps and square roots of T = double or Lanes<kNativeLanes>, for code written
// once over both (one element, or one element per lane: the same operations, so the same
// bits). The lanes' are next_up, next_down and sqrt's bits (symmetric3_lanes.hpp).
// Internal to src/analysis; a file brings them in with `using namespace scalar_or_lanes;`.
#include "analysis/lane_vector.hpp"
#include "analysis/outward_rounding.hpp"
#include "analysis/sqrt_rn.hpp"
#include "analysis/symmetric3_lanes.hpp"

namespace quadval::scalar_or_lanes {

using LaneBlock = Lanes<kNativeLanes>;
inline double up(double x) { return next_up(x); }
inline double down(double x) { return next_down(x); }
inline double root(double x) { return sqrt_rn(x); }
inline LaneBlock up(LaneBlock x) { return lanes3::up<kNativeLanes>(x); }
inline LaneBlock down(LaneBlock x) { return lanes3::down<kNativeLanes>(x); }
inline LaneBlock root(LaneBlock x) { return lanes3::root<kNativeLanes>(x); }

}  // namespace quadval::scalar_or_lanes
