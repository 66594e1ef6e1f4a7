// The batched path that `quadval check` runs (check_mesh: chunks of elements, J's Bézier
// coefficients in SIMD lane blocks plus a scalar tail) gives bit-identical answers to the
// single-element jacobian_bounds, on random curved elements of every family and order up
// to 3. Both are certified (the other analysis tests check that against exact and sampled
// oracles); this test pins down that batching changes nothing, not even the last bit.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "analysis/jacobian_space.hpp"
#include "analysis/linear_jacobian.hpp"
#include "jacobian_test_util.hpp"
#include "quadval/check_report.hpp"
#include "quadval/jacobian_bounds.hpp"

namespace quadval {
namespace {

// Every analysed type up to order 3, pyramids included.
std::vector<const ElementType*> types_up_to_3() {
  std::vector<const ElementType*> out = test::analysed_types(3, 3);
  for (const ElementType& t : element_types())
    if (t.family == ElementFamily::pyramid && t.has_lagrange_basis && t.order >= 1 && t.order <= 3 &&
        jacobian_supported(t))
      out.push_back(&t);
  return out;
}

// One block of `count` random curved elements of `type`, each with its own nodes.
Mesh random_block(const ElementType& type, std::size_t count, double amplitude, std::mt19937& rng,
                  std::vector<std::vector<double>>& elements) {
  elements.clear();
  for (std::size_t e = 0; e < count; ++e) elements.push_back(test::random_element(type, amplitude, rng));
  return test::mesh_of_elements(type, elements);
}

void expect_identical(const JacobianBounds& a, const JacobianBounds& b, const std::string& what) {
  EXPECT_EQ(a.jmin_lower, b.jmin_lower) << what;
  EXPECT_EQ(a.jmin_upper, b.jmin_upper) << what;
  EXPECT_EQ(a.jmax_lower, b.jmax_lower) << what;
  EXPECT_EQ(a.jmax_upper, b.jmax_upper) << what;
  EXPECT_EQ(a.javg, b.javg) << what;
  EXPECT_EQ(a.validity, b.validity) << what;
  EXPECT_EQ(a.subdivisions, b.subdivisions) << what;
  EXPECT_EQ(a.stage, b.stage) << what;
  EXPECT_EQ(a.exact, b.exact) << what;
  EXPECT_EQ(a.tolerance_met, b.tolerance_met) << what;
}

// check_mesh against jacobian_bounds, element by element, in both goals. 300 elements: a
// full chunk of 256 and a partial one, whose 44 = 5 lane blocks of 8 + a tail of 4. The
// single-element bounds take the general path even where check decides in one pass over
// the first coefficients (BoundsOptions::one_pass_decision), so that is compared too.
void compare(CheckMeasure measure, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::size_t answers[3] = {0, 0, 0}, subdivided = 0;
  for (const ElementType* type : types_up_to_3()) {
    // Validity: the first-order types with a fast path take it instead (its own bounds,
    // linear_fast_path_test.cpp); measuring, they take the product path like the rest.
    if (measure == CheckMeasure::validity && linear_kind(*type, /*planar=*/true) != LinearKind::none)
      continue;
    std::vector<std::vector<double>> elements;
    const Mesh mesh = random_block(*type, count, 0.12, rng, elements);
    CheckOptions o;
    o.measure = measure;
    o.threads = 2;
    const CheckReport r = check_mesh(mesh, o);
    ASSERT_EQ(r.elements.size(), count);
    BoundsOptions bo;
    bo.goal = measure == CheckMeasure::validity ? BoundsGoal::validity : BoundsGoal::measure;
    bo.one_pass_decision = false;  // the general path, against check's one-pass decision
    BoundsWorkspace ws;
    const bool planar = type->dim == 2;  // random_element puts 2D elements in z = 0
    for (std::size_t e = 0; e < count; ++e) {
      const JacobianBounds single = jacobian_bounds(*type, elements[e], bo, ws, planar);
      ASSERT_TRUE(r.elements[e].analysed) << type->name;
      expect_identical(r.elements[e].bounds, single, std::string(type->name) + " element " + std::to_string(e));
      ++answers[static_cast<int>(single.validity)];
      if (single.subdivisions > 0) ++subdivided;
    }
  }
  // The random elements exercise all three stages that matter: decided by the first
  // coefficients, after subdivision, and invalid.
  EXPECT_GT(answers[static_cast<int>(Validity::valid)], 0u);
  EXPECT_GT(answers[static_cast<int>(Validity::invalid)], 0u);
  EXPECT_GT(subdivided, 0u);
}

TEST(JacobianBatch, CheckValidityIsBitIdenticalToSingleElementBounds) {
  compare(CheckMeasure::validity, 300, 5);
}

TEST(JacobianBatch, CheckMeasureIsBitIdenticalToSingleElementBounds) {
  compare(CheckMeasure::jacobian, 60, 6);
}

// The coefficient kernel alone: a batch (lane blocks + scalar tail) equals the elements
// computed one at a time, for both maps and, in 2D, both reference vectors.
TEST(JacobianBatch, CoefficientsDoNotDependOnTheBatch) {
  std::mt19937 rng(7);
  for (const ElementType* type : types_up_to_3()) {
    const JacobianSpace& space = jacobian_space(*type);
    ASSERT_NE(space.product(), nullptr) << type->name;
    const auto s = static_cast<std::size_t>(space.basis().size());
    const std::size_t count = 19;  // 2 lane blocks + 3
    std::vector<double> nodes;
    for (std::size_t e = 0; e < count; ++e) {
      const auto x = test::random_element(*type, 0.2, rng);
      nodes.insert(nodes.end(), x.begin(), x.end());
    }
    const std::size_t stride = static_cast<std::size_t>(type->num_nodes) * 3;
    for (SampleMap map : {SampleMap::curved, SampleMap::straight})
      for (bool planar : {true, false}) {
        if (planar && type->dim != 2) continue;
        std::vector<double> batch(count * s), batch_err(count), one(s);
        double one_err = 0;
        ProductScratch scratch;
        space.product()->coefficients(map, nodes.data(), count, planar, batch.data(), batch_err.data(), scratch);
        for (std::size_t e = 0; e < count; ++e) {
          space.product()->coefficients(map, nodes.data() + e * stride, 1, planar, one.data(), &one_err, scratch);
          EXPECT_EQ(batch_err[e], one_err) << type->name << " element " << e;
          for (std::size_t k = 0; k < s; ++k)
            ASSERT_EQ(batch[e * s + k], one[k]) << type->name << " element " << e << " coefficient " << k;
        }
      }
  }
}

}  // namespace
}  // namespace quadval
