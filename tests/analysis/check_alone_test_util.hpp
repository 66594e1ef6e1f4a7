#pragma once
// The check against each element alone: for the lane paths of the check's chunks, which
// must give every element the bits its own call gives it.
#include <gtest/gtest.h>

#include <vector>

#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/element_type.hpp"
#include "quadval/quality_bounds.hpp"

namespace quadval::test {

// check_mesh of `elements` (all of `type`) for `measure`, on two threads: each element's
// bounds (of mu or of the scaled Jacobian, as `measure`) bit for bit those `alone` gives
// it; returns how many of them have a positive lower bound.
template <class Alone>
inline int expect_check_matches_alone(const ElementType& type, const std::vector<std::vector<double>>& elements,
                                      CheckMeasure measure, Alone alone) {
  CheckOptions o;
  o.measure = measure;
  o.threads = 2;
  const CheckReport r = check_mesh(mesh_of_elements(type, elements), o);
  const std::vector<QualityBounds>& got = measure == CheckMeasure::mu ? r.mu : r.sj;
  EXPECT_EQ(got.size(), elements.size());
  if (got.size() != elements.size()) return 0;
  QualityOptions q;
  q.abs_tol = o.quality_abs_tol;
  int positive = 0;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const QualityBounds own = alone(elements[e], q);
    EXPECT_EQ(got[e].lower, own.lower) << "element " << e;
    EXPECT_EQ(got[e].upper, own.upper) << "element " << e;
    EXPECT_EQ(got[e].subdivisions, own.subdivisions) << "element " << e;
    EXPECT_EQ(got[e].tolerance_met, own.tolerance_met) << "element " << e;
    if (own.lower > 0) ++positive;
  }
  return positive;
}

}  // namespace quadval::test
