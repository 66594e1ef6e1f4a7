// Reports of check_mesh: terminal summary (with Paper III Table 2's stage table), CSV,
// JSON and per-element mesh fields.
#include <fmt/core.h>
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <tuple>
#include <vector>
#include <nlohmann/json.hpp>

#include "quadval/check_report.hpp"

namespace quadval {
namespace {

const char* measure_name(CheckMeasure m) { return check_measure_name(m); }

std::string num(double x) { return std::isnan(x) ? "nan" : fmt::format("{:.17g}", x); }

const char* answer(const ElementCheck& e) {
  return e.analysed ? validity_name(e.bounds.validity) : "skipped";
}

// The scale-free quality the histogram and the worst list use.
double quality(const CheckReport& r, std::size_t i) {
  return measures_distortion(r.measure) ? r.distortion_of(i).lower : r.elements[i].ratio_lower();
}

// Histogram lines of values in [-1, 1] (bins of 0.1 from 0, one bin below 0).
void histogram(std::string& out, const std::vector<double>& values) {
  static constexpr double kEdges[] = {-INFINITY, 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, INFINITY};
  std::array<std::size_t, 11> bins{};
  for (double q : values)
    for (std::size_t b = 0; b < bins.size(); ++b)
      if (q >= kEdges[b] && q < kEdges[b + 1]) ++bins[b];
  for (std::size_t b = 0; b < bins.size(); ++b) {
    const std::string label = b == 0 ? "< 0" : b + 1 == bins.size() ? ">= 0.9" : fmt::format("[{:.1f}, {:.1f})", kEdges[b], kEdges[b + 1]);
    const std::size_t width = values.empty() ? 0 : (bins[b] * 40 + values.size() - 1) / values.size();
    out += fmt::format("  {:>12} {:>9} {}\n", label, bins[b], std::string(width, '#'));
  }
}

// The summary section of mu (sj = false) or the scaled Jacobian (sj = true).
void quality_section(std::string& out, const CheckReport& r, bool sj, std::size_t worst) {
  const QualityCounts& qc = sj ? r.sj_counts : r.mu_counts;
  const char* name = sj ? "scaled Jacobian" : "mu";
  std::vector<double> lows;
  double sum = 0;
  for (std::size_t i = 0; i < r.elements.size(); ++i) {
    const double lo = (sj ? r.sj_of(i) : r.mu_of(i)).lower;
    if (std::isnan(lo)) continue;
    lows.push_back(lo);
    sum += lo;
  }
  out += fmt::format("  {} ({}): computed {}, skipped {}, tolerance not met {}\n", name,
                     sj ? "min of det J / product of column norms, corner frames for simplices"
                        : "min of sqrt(lambda_min / lambda_max) of W^T W, Paper V",
                     qc.computed, qc.skipped, qc.tolerance_not_met);
  for (const auto& [id, n] : qc.skipped_types) {
    const ElementType* t = find_element_type(id);
    out += fmt::format("  note: {} {} skipped for {}: type or order not supported\n", n, t ? t->name : "?", name);
  }
  if (lows.empty()) {
    out += "\n";
    return;
  }
  const std::size_t lowest = r.worst_quality(1, sj).front();
  out += fmt::format("  {} lower bounds: min {:.6g} (element {}), mean {:.6g}\n", name,
                     (sj ? r.sj_of(lowest) : r.mu_of(lowest)).lower, r.elements[lowest].tag, sum / static_cast<double>(lows.size()));
  out += fmt::format("  histogram of the {} lower bounds\n", name);
  histogram(out, lows);
  const auto wl = r.worst_quality(worst, sj);
  if (!wl.empty()) {
    out += fmt::format("  worst {} elements by {}\n", wl.size(), name);
    out += fmt::format("  {:>10} {:<22} {:<13} {:>13} {:>13} {:>8}\n", "tag", "type", "validity", "lower", "upper", "subdiv");
    for (std::size_t i : wl) {
      const ElementCheck& e = r.elements[i];
      const QualityBounds q = sj ? r.sj_of(i) : r.mu_of(i);
      out += fmt::format("  {:>10} {:<22} {:<13} {:>13.6g} {:>13.6g} {:>8}\n", e.tag, e.type->name, answer(e), q.lower,
                         q.upper, q.subdivisions);
    }
  }
  out += "\n";
}

}  // namespace

const char* check_measure_name(CheckMeasure m) noexcept {
  switch (m) {
    case CheckMeasure::validity: return "validity";
    case CheckMeasure::jacobian: return "jacobian";
    case CheckMeasure::distortion: return "distortion";
    case CheckMeasure::mu: return "mu";
    case CheckMeasure::scaled_jacobian: return "scaled-jacobian";
    case CheckMeasure::all: return "all";
  }
  return "?";
}
bool measures_mu(CheckMeasure m) noexcept { return m == CheckMeasure::mu || m == CheckMeasure::all; }
bool measures_scaled_jacobian(CheckMeasure m) noexcept {
  return m == CheckMeasure::scaled_jacobian || m == CheckMeasure::all;
}
bool measures_jacobian_range(CheckMeasure m) noexcept {
  return m == CheckMeasure::jacobian || m == CheckMeasure::distortion || m == CheckMeasure::all;
}
bool measures_distortion(CheckMeasure m) noexcept {
  return m == CheckMeasure::distortion || m == CheckMeasure::all;
}

std::string format_check_summary(const CheckReport& r, std::size_t worst) {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line(fmt::format("[check] {}: {} elements of dimension {}{}, measure {}, {} thread{}, {:.3f} s",
                   r.file, r.elements.size(), r.dimension,
                   r.dimension == 2 ? (r.planar ? " (planar: J with n = +z)" : " (J with each element's normal)") : "",
                   measure_name(r.measure), r.threads, r.threads == 1 ? "" : "s", r.seconds));
  line(fmt::format("[check] valid {}, invalid {}, undetermined {}, skipped {}", r.count(Validity::valid),
                   r.count(Validity::invalid), r.count(Validity::undetermined), r.skipped()));
  line("");
  line(fmt::format("  {:<26} {:>10} {:>10} {:>13} {:>9}", "type", "valid", "invalid", "undetermined", "skipped"));
  for (const auto& [id, c] : r.counts) {
    const ElementType* t = find_element_type(id);
    line(fmt::format("  {:<26} {:>10} {:>10} {:>13} {:>9}", fmt::format("{} ({})", t ? t->name : "?", id),
                     c[0], c[1], c[2], c[3]));
  }
  for (const auto& [id, c] : r.counts)
    if (c[3] > 0) {
      const ElementType* t = find_element_type(id);
      line(fmt::format("  note: {} {} not analysed: type or order beyond the supported ones "
                       "(max_supported_order)", c[3], t ? t->name : "?"));
    }
  line("");
  line("  stage table (Paper III Table 2; time = CPU seconds over threads)");
  line(fmt::format("  {:<18} {:>10} {:>10} {:>12}", "stage", "valid", "invalid", "time [s]"));
  for (const StageRow& s : r.stages)
    line(fmt::format("  {:<18} {:>10} {:>10} {:>12.4g}", s.name, s.valid, s.invalid, s.seconds));
  line(fmt::format("  {:<18} {:>10}", "undetermined", r.count(Validity::undetermined)));
  line(fmt::format("  exact-arithmetic fallbacks: {}", r.exact_fallbacks));
  line("");

  // Histogram of the scale-free quality.
  const char* qname = measures_distortion(r.measure) ? "distortion lower bound (min J / J_straight)"
                                                            : "min J / max J lower bound";
  static constexpr double kEdges[] = {-INFINITY, 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, INFINITY};
  std::array<std::size_t, 11> bins{};
  std::size_t undefined = 0, total = 0;
  for (std::size_t i = 0; i < r.elements.size(); ++i) {
    if (!r.elements[i].analysed) continue;
    const double q = quality(r, i);
    if (std::isnan(q)) {
      ++undefined;
      continue;
    }
    ++total;
    for (std::size_t b = 0; b < bins.size(); ++b)
      if (q >= kEdges[b] && q < kEdges[b + 1]) ++bins[b];
  }
  line(fmt::format("  histogram of the {}", qname));
  for (std::size_t b = 0; b < bins.size(); ++b) {
    const std::string label = b == 0 ? "< 0" : b + 1 == bins.size() ? ">= 0.9" : fmt::format("[{:.1f}, {:.1f})", kEdges[b], kEdges[b + 1]);
    const std::size_t width = total ? (bins[b] * 40 + total - 1) / total : 0;
    line(fmt::format("  {:>12} {:>9} {}", label, bins[b], std::string(width, '#')));
  }
  if (undefined) line(fmt::format("  {:>12} {:>9}", "undefined", undefined));
  line("");

  const auto w = r.worst(worst);
  if (!w.empty()) {
    line(fmt::format("  worst {} elements", w.size()));
    line(fmt::format("  {:>10} {:<22} {:<13} {:>13} {:>13} {:>11}", "tag", "type", "validity", "jmin_lower",
                     "jmin_upper", measures_distortion(r.measure) ? "distortion" : "ratio"));
    for (std::size_t i : w) {
      const ElementCheck& e = r.elements[i];
      line(fmt::format("  {:>10} {:<22} {:<13} {:>13.6g} {:>13.6g} {:>11.5g}", e.tag, e.type->name, answer(e),
                       e.bounds.jmin_lower, e.bounds.jmin_upper, quality(r, i)));
    }
  }
  const bool mu = measures_mu(r.measure), sj = measures_scaled_jacobian(r.measure);
  if (mu || sj) {
    line("");
    if (mu) quality_section(out, r, false, worst);
    if (sj) quality_section(out, r, true, worst);
    line("  note: certified bounds (lower <= min over the element <= upper, within --tol). Gmsh's");
    line("  AnalyseCurvedMesh ICN/IGE are related but not equal measures, and not certified bounds.");
  }
  return out;
}

std::string check_csv(const CheckReport& r) {
  std::string out =
      "tag,type,validity,jmin_lower,jmin_upper,jmax_lower,jmax_upper,distortion_lower,subdivisions,"
      "distortion_upper,jmin_over_javg,ratio_lower,stage,exact,mu_lower,mu_upper,sj_lower,sj_upper\n";
  for (std::size_t i = 0; i < r.elements.size(); ++i) {
    const ElementCheck& e = r.elements[i];
    const JacobianBounds& b = e.bounds;
    const DistortionBounds d = r.distortion_of(i);
    const QualityBounds mu = r.mu_of(i), sj = r.sj_of(i);
    if (!e.analysed) {
      out += fmt::format("{},{},skipped,nan,nan,nan,nan,nan,0,nan,nan,nan,-1,0,nan,nan,nan,nan\n", e.tag, e.type->gmsh_id);
      continue;
    }
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", e.tag, e.type->gmsh_id, answer(e),
                       num(b.jmin_lower), num(b.jmin_upper), num(b.jmax_lower), num(b.jmax_upper),
                       num(d.lower), b.subdivisions, num(d.upper),
                       num(e.jmin_over_javg()), num(e.ratio_lower()), b.stage, b.exact ? 1 : 0, num(mu.lower),
                       num(mu.upper), num(sj.lower), num(sj.upper));
  }
  return out;
}

std::string check_json(const CheckReport& r) {
  using nlohmann::json;
  const auto jnum = [](double x) { return std::isnan(x) ? json(nullptr) : json(x); };
  json summary = {{"file", r.file},
                  {"measure", measure_name(r.measure)},
                  {"dimension", r.dimension},
                  {"planar", r.planar},
                  {"elements", r.elements.size()},
                  {"valid", r.count(Validity::valid)},
                  {"invalid", r.count(Validity::invalid)},
                  {"undetermined", r.count(Validity::undetermined)},
                  {"skipped", r.skipped()},
                  {"exact_fallbacks", r.exact_fallbacks},
                  {"seconds", r.seconds},
                  {"threads", r.threads}};
  json types = json::object();
  for (const auto& [id, c] : r.counts) {
    const ElementType* t = find_element_type(id);
    types[std::string(t ? t->name : "?")] = {{"gmsh_type", id}, {"valid", c[0]}, {"invalid", c[1]},
                                             {"undetermined", c[2]}, {"skipped", c[3]}};
  }
  summary["types"] = types;
  for (const auto& [key, qc, on] : {std::tuple{"mu", &r.mu_counts, measures_mu(r.measure)},
                                    std::tuple{"scaled_jacobian", &r.sj_counts, measures_scaled_jacobian(r.measure)}}) {
    if (!on) continue;
    json q = {{"computed", qc->computed}, {"skipped", qc->skipped}, {"tolerance_not_met", qc->tolerance_not_met}};
    const auto w = r.worst_quality(10, std::string(key) != "mu");
    json tags = json::array();
    for (std::size_t i : w) tags.push_back(r.elements[i].tag);
    q["worst_tags"] = tags;
    summary[key] = q;
  }
  json stages = json::array();
  for (const StageRow& s : r.stages)
    stages.push_back({{"stage", s.name}, {"valid", s.valid}, {"invalid", s.invalid}, {"cpu_seconds", s.seconds}});
  summary["stages"] = stages;
  json worst = json::array();
  for (std::size_t i : r.worst(10)) worst.push_back(r.elements[i].tag);
  summary["worst_tags"] = worst;
  json elements = json::array();
  for (std::size_t i = 0; i < r.elements.size(); ++i) {
    const ElementCheck& e = r.elements[i];
    const JacobianBounds& b = e.bounds;
    const DistortionBounds d = r.distortion_of(i);
    const QualityBounds mu = r.mu_of(i), sj = r.sj_of(i);
    json je = {{"tag", e.tag}, {"type", e.type->gmsh_id}, {"validity", answer(e)}};
    if (e.analysed) {
      je["jmin"] = {jnum(b.jmin_lower), jnum(b.jmin_upper)};
      je["jmax"] = {jnum(b.jmax_lower), jnum(b.jmax_upper)};
      je["distortion"] = {jnum(d.lower), jnum(d.upper)};
      je["ratio_lower"] = jnum(e.ratio_lower());
      je["jmin_over_javg"] = jnum(e.jmin_over_javg());
      je["subdivisions"] = b.subdivisions;
      je["stage"] = b.stage;
      je["exact"] = b.exact;
      for (const auto& [name, q] : {std::pair{"mu", mu}, std::pair{"sj", sj}})
        if (!std::isnan(q.lower))
          je[name] = {{"lower", q.lower}, {"upper", q.upper}, {"subdivisions", q.subdivisions},
                      {"tolerance_met", q.tolerance_met}};
    }
    elements.push_back(std::move(je));
  }
  return json({{"summary", summary}, {"elements", elements}}).dump(1) + "\n";
}

std::vector<std::pair<std::string, std::vector<double>>> check_fields(const Mesh& mesh,
                                                                      const CheckReport& r) {
  std::vector<std::pair<std::string, std::vector<double>>> f = {
      {"validity", {}}, {"jmin_lower", {}}, {"jmin_upper", {}}, {"ratio_lower", {}}, {"distortion_lower", {}},
      {"mu_lower", {}}, {"sj_lower", {}}};
  std::size_t k = 0;
  for (const ElementBlock& b : mesh.blocks) {
    const bool analysed_dim = b.type->dim == r.dimension;
    for (std::size_t e = 0; e < b.size(); ++e) {
      double v = NAN, lo = NAN, hi = NAN, ratio = NAN, dist = NAN, mu = NAN, sj = NAN;
      if (analysed_dim) {
        const ElementCheck& c = r.elements[k++];
        if (c.analysed) {
          v = c.bounds.validity == Validity::valid ? 1 : c.bounds.validity == Validity::invalid ? -1 : 0;
          lo = c.bounds.jmin_lower;
          hi = c.bounds.jmin_upper;
          ratio = c.ratio_lower();
          dist = r.distortion_of(k - 1).lower;
          mu = r.mu_of(k - 1).lower;
          sj = r.sj_of(k - 1).lower;
        }
      }
      f[0].second.push_back(v);
      f[1].second.push_back(lo);
      f[2].second.push_back(hi);
      f[3].second.push_back(ratio);
      f[4].second.push_back(dist);
      f[5].second.push_back(mu);
      f[6].second.push_back(sj);
    }
  }
  // mu_lower and sj_lower only when the measure computed them.
  if (!measures_scaled_jacobian(r.measure)) f.erase(f.begin() + 6);
  if (!measures_mu(r.measure)) f.erase(f.begin() + 5);
  return f;
}

}  // namespace quadval
