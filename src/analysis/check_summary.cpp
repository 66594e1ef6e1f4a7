// The summary of a check (Paper III §5: counts, worst elements, histogram, stage table),
// kept while elements stream by, or computed from a stored report as its reference.
#include "analysis/check_summary.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

namespace quadval {
namespace {

constexpr double kEdges[QualityHistogram::kBins + 1] = {-INFINITY, 0,   0.1, 0.2, 0.3, 0.4,
                                                        0.5,       0.6, 0.7, 0.8, 0.9, INFINITY};

// The worst lists' order: key (NaN lowest), then tag, then index (unique).
bool lower_than(const WorstElement& a, const WorstElement& b) {
  const double ka = std::isnan(a.key) ? -INFINITY : a.key;
  const double kb = std::isnan(b.key) ? -INFINITY : b.key;
  if (ka != kb) return ka < kb;
  if (a.tag != b.tag) return a.tag < b.tag;
  return a.index < b.index;
}

// The scale-free quality of the summary's histogram and worst list.
double quality_key(CheckMeasure m, const ElementCheck& e, const DistortionBounds& d) {
  return measures_distortion(m) ? d.lower : e.ratio_lower();
}

WorstElement worst_entry(std::size_t index, const ElementCheck& e, double key,
                         const QualityBounds& q = kNotComputed) {
  WorstElement w;
  w.index = index;
  w.tag = e.tag;
  w.type = e.type;
  w.key = key;
  w.bounds = e.bounds;
  w.quality = q;
  return w;
}

}  // namespace

void QualityHistogram::add(double q) noexcept {
  if (std::isnan(q)) {
    ++undefined;
    return;
  }
  ++values;
  if (!(q < kEdges[kBins])) return;  // +infinity: counted, in no bin (as q < inf fails)
  // A first guess from q * 10, then moved to the bin whose edges hold q: the same bin as
  // testing every edge, without the loop.
  std::size_t b = q < 0 ? 0 : q >= 0.9 ? kBins - 1 : 1 + static_cast<std::size_t>(q * 10);
  while (b > 0 && q < kEdges[b]) --b;
  while (b + 1 < kBins && q >= kEdges[b + 1]) ++b;
  ++bins[b];
}

std::string QualityHistogram::label(std::size_t b) {
  if (b == 0) return "< 0";
  if (b + 1 == kBins) return ">= 0.9";
  return fmt::format("[{:.1f}, {:.1f})", kEdges[b], kEdges[b + 1]);
}

void WorstList::offer(const WorstElement& e) {
  if (capacity_ == 0) return;
  if (heap_.size() < capacity_) {
    heap_.push_back(e);
    std::push_heap(heap_.begin(), heap_.end(), lower_than);
  } else if (lower_than(e, heap_.front())) {
    std::pop_heap(heap_.begin(), heap_.end(), lower_than);
    heap_.back() = e;
    std::push_heap(heap_.begin(), heap_.end(), lower_than);
  }
}

std::vector<WorstElement> WorstList::sorted() const {
  std::vector<WorstElement> out = heap_;
  std::sort(out.begin(), out.end(), lower_than);
  return out;
}

std::size_t CheckSummary::count(Validity v) const {
  std::size_t n = 0;
  for (const auto& [id, c] : counts) n += c[static_cast<std::size_t>(v)];
  return n;
}

std::size_t CheckSummary::skipped() const {
  std::size_t n = 0;
  for (const auto& [id, c] : counts) n += c[3];
  return n;
}

DistortionBounds CheckBatch::distortion_of(std::size_t i) const noexcept {
  return distortion.empty() ? DistortionBounds{NAN, NAN} : distortion[i];
}

QualityBounds CheckBatch::mu_of(std::size_t i) const noexcept { return mu.empty() ? kNotComputed : mu[i]; }

QualityBounds CheckBatch::sj_of(std::size_t i) const noexcept { return sj.empty() ? kNotComputed : sj[i]; }

CheckSummary empty_summary(const std::string& file, CheckMeasure measure, std::size_t worst) {
  CheckSummary s;
  s.file = file;
  s.measure = measure;
  const std::size_t keep = std::max<std::size_t>(worst, 10);
  s.worst = WorstList(keep);
  s.mu.worst = WorstList(keep);
  s.sj.worst = WorstList(keep);
  return s;
}

void add_elements(CheckSummary& s, const CheckBatch& b, std::size_t from, std::size_t to) {
  const bool by_distortion = measures_distortion(s.measure);
  for (std::size_t i = from; i < to; ++i) {
    const ElementCheck& e = b.elements[i];
    if (!e.analysed) continue;
    const double q = by_distortion ? b.distortion_of(i).lower : e.ratio_lower();
    s.histogram.add(q);
    if (s.worst.may_take(q)) s.worst.offer(worst_entry(b.first + i, e, q));
  }
  // mu and the scaled Jacobian where measured (NaN lower bounds: not computed).
  for (auto [on, values, summary] : {std::tuple{measures_mu(s.measure), b.mu, &s.mu},
                                     std::tuple{measures_scaled_jacobian(s.measure), b.sj, &s.sj}}) {
    if (!on) continue;
    for (std::size_t i = from; i < to && !values.empty(); ++i) {
      const QualityBounds& bounds = values[i];
      if (std::isnan(bounds.lower)) continue;
      summary->histogram.add(bounds.lower);
      if (summary->worst.may_take(bounds.lower))
        summary->worst.offer(worst_entry(b.first + i, b.elements[i], bounds.lower, bounds));
    }
  }
}

void add_sums(CheckSummary& s, const CheckBatch& b) {
  for (auto [values, summary] : {std::pair{b.mu, &s.mu}, std::pair{b.sj, &s.sj}})
    for (const QualityBounds& q : values)
      if (!std::isnan(q.lower)) summary->lower_sum += q.lower;
}

void merge_summary(CheckSummary& into, const CheckSummary& part) {
  const auto merge = [](QualityHistogram& h, const QualityHistogram& p) {
    for (std::size_t k = 0; k < QualityHistogram::kBins; ++k) h.bins[k] += p.bins[k];
    h.values += p.values;
    h.undefined += p.undefined;
  };
  merge(into.histogram, part.histogram);
  merge(into.mu.histogram, part.mu.histogram);
  merge(into.sj.histogram, part.sj.histogram);
  for (const WorstElement& e : part.worst.sorted()) into.worst.offer(e);
  for (const WorstElement& e : part.mu.worst.sorted()) into.mu.worst.offer(e);
  for (const WorstElement& e : part.sj.worst.sorted()) into.sj.worst.offer(e);
}

CheckSummary summarize(const CheckReport& r, std::size_t worst) {
  CheckSummary s = empty_summary(r.file, r.measure, worst);
  s.dimension = r.dimension;
  s.planar = r.planar;
  s.elements = r.elements.size();
  s.counts = r.counts;
  s.stages = r.stages;
  s.exact_fallbacks = r.exact_fallbacks;
  s.seconds = r.seconds;
  s.threads = r.threads;
  s.mu.counts = r.mu_counts;
  s.sj.counts = r.sj_counts;
  // Histograms and sums over every element in order; worst lists by sorting them all.
  for (std::size_t i = 0; i < r.elements.size(); ++i) {
    const ElementCheck& e = r.elements[i];
    if (e.analysed) s.histogram.add(quality_key(r.measure, e, r.distortion_of(i)));
    for (auto [bounds, summary] : {std::pair{r.mu_of(i), &s.mu}, std::pair{r.sj_of(i), &s.sj}}) {
      if (std::isnan(bounds.lower)) continue;
      summary->histogram.add(bounds.lower);
      summary->lower_sum += bounds.lower;
    }
  }
  const std::size_t keep = s.worst.capacity();
  for (std::size_t i : r.worst(keep))
    s.worst.offer(worst_entry(i, r.elements[i], quality_key(r.measure, r.elements[i], r.distortion_of(i))));
  for (std::size_t i : r.worst_quality(keep, false)) s.mu.worst.offer(worst_entry(i, r.elements[i], r.mu_of(i).lower, r.mu_of(i)));
  for (std::size_t i : r.worst_quality(keep, true)) s.sj.worst.offer(worst_entry(i, r.elements[i], r.sj_of(i).lower, r.sj_of(i)));
  return s;
}

}  // namespace quadval
