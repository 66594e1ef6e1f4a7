// check_mesh's thread count: extra threads only for work worth them (each costs its wake-up
// and the closing barrier, milliseconds on busy cores), and with several threads the
// answers are those of one thread, bit for bit, whether the threads start at once or on
// demand (mid-run). The other determinism tests run meshes small enough to stay on one
// thread; this one is large enough for two.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"

namespace quadval {
namespace {

// `count` random curved elements of `type` (each with its own nodes) in one block.
Mesh random_mesh(const ElementType& type, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<double>> elements;
  for (std::size_t e = 0; e < count; ++e) elements.push_back(test::random_element(type, 0.12, rng));
  return test::mesh_of_elements(type, elements);
}

TEST(CheckThreads, SmallMeshRunsOnOneThread) {
  const Mesh mesh = random_mesh(*find_element_type(ElementFamily::tetrahedron, 2, true), 600, 1);
  CheckOptions o;
  o.threads = 4;
  EXPECT_EQ(check_mesh(mesh, o).threads, 1);  // 600 x 10 nodes x 20 coefficients: ~0.1 ms of work
}

TEST(CheckThreads, LargeWorkUsesThreadsWithIdenticalAnswers) {
  // Validity: 3000 x 20 nodes x 84 coefficients = 5.04e6 work units, six threads' worth.
  const Mesh mesh = random_mesh(*find_element_type(ElementFamily::tetrahedron, 3, true), 3000, 2);
  CheckOptions o;
  o.threads = 1;
  const CheckReport one = check_mesh(mesh, o);
  o.threads = 8;  // capped by the work, not by the chunks (12)
  o.threads_on_demand = false;
  const CheckReport many = check_mesh(mesh, o);
  o.threads_on_demand = true;  // (started mid-run or not at all, as the machine's pace says)
  const CheckReport on_demand = check_mesh(mesh, o);
  EXPECT_EQ(one.threads, 1);
  EXPECT_EQ(many.threads, 6);
  EXPECT_TRUE(on_demand.threads == 1 || on_demand.threads == 6) << on_demand.threads;
  EXPECT_EQ(check_csv(one), check_csv(on_demand));
  ASSERT_EQ(one.elements.size(), many.elements.size());
  std::size_t answers[3] = {0, 0, 0};
  for (std::size_t e = 0; e < one.elements.size(); ++e) {
    const JacobianBounds& a = one.elements[e].bounds;
    const JacobianBounds& b = many.elements[e].bounds;
    ASSERT_EQ(a.validity, b.validity) << e;
    ASSERT_EQ(a.jmin_lower, b.jmin_lower) << e;
    ASSERT_EQ(a.jmin_upper, b.jmin_upper) << e;
    ASSERT_EQ(a.jmax_lower, b.jmax_lower) << e;
    ASSERT_EQ(a.jmax_upper, b.jmax_upper) << e;
    ASSERT_EQ(a.subdivisions, b.subdivisions) << e;
    ++answers[static_cast<int>(a.validity)];
  }
  EXPECT_EQ(check_csv(one), check_csv(many));
  // Both answers occur, so the comparison covers more than one code path.
  EXPECT_GT(answers[static_cast<int>(Validity::valid)], 0u);
  EXPECT_GT(answers[static_cast<int>(Validity::invalid)], 0u);
}

TEST(CheckThreads, MeasuringCountsAsMoreWork) {
  // One thread per 1e6 units (node x J coefficient, weighed 50 times when measuring),
  // capped by the chunks (64 curved elements each) and by the threads requested. 128
  // tetrahedra of order 3 (two chunks): 128 x 20 x 84 = 2.15e5 units for validity, one
  // thread; 1.08e7 measuring, capped by the two chunks.
  const Mesh small = random_mesh(*find_element_type(ElementFamily::tetrahedron, 3, true), 128, 3);
  CheckOptions o;
  o.threads = 8;
  o.threads_on_demand = false;  // the estimate's count, not the pace of this machine
  o.measure = CheckMeasure::validity;
  EXPECT_EQ(check_mesh(small, o).threads, 1);
  o.measure = CheckMeasure::jacobian;
  EXPECT_EQ(check_mesh(small, o).threads, 2);
  // 3000 tetrahedra of order 3 (47 chunks): 3000 x 20 x 84 = 5.04e6 units for validity,
  // six threads; 2.5e8 measuring: capped by the 8 requested.
  const Mesh big = random_mesh(*find_element_type(ElementFamily::tetrahedron, 3, true), 3000, 4);
  o.measure = CheckMeasure::validity;
  EXPECT_EQ(check_mesh(big, o).threads, 6);
  o.measure = CheckMeasure::jacobian;
  EXPECT_EQ(check_mesh(big, o).threads, 8);
}

TEST(CheckThreads, OnDemandStartsAtOnceForLargeEstimates) {
  // 3000 tetrahedra of order 3 measured: 2.5e8 units, above the threshold of an immediate
  // start (3e7), so the count is the estimate's whatever the pace: 8 requested.
  const Mesh big = random_mesh(*find_element_type(ElementFamily::tetrahedron, 3, true), 3000, 4);
  CheckOptions o;
  o.threads = 8;
  o.measure = CheckMeasure::jacobian;
  EXPECT_EQ(check_mesh(big, o).threads, 8);
  // A tiny job: one thread (128 x 20 x 84 = 2.15e5 units, one thread's worth).
  const Mesh small = random_mesh(*find_element_type(ElementFamily::tetrahedron, 3, true), 128, 3);
  o.measure = CheckMeasure::validity;
  EXPECT_EQ(check_mesh(small, o).threads, 1);
}

}  // namespace
}  // namespace quadval
