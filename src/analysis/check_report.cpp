// Reports of check_mesh: terminal summary (with Paper III Table 2's stage table), CSV,
// JSON and per-element mesh fields.
#include <fmt/core.h>
#include <fmt/compile.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <ostream>
#include <sstream>
#include <tuple>
#include <vector>
#include <nlohmann/json.hpp>

#include "quadval/check_report.hpp"

namespace quadval {
namespace {

const char* measure_name(CheckMeasure m) { return check_measure_name(m); }

// A double for CSV: fmt's {} prints the shortest text that reads back to the same double,
// and "nan" for a NaN without its sign bit ("-nan" with it, as 0/0 gives on x86).
double num(double x) { return std::isnan(x) ? std::numeric_limits<double>::quiet_NaN() : x; }

const char* answer(const ElementCheck& e) {
  return e.analysed ? validity_name(e.bounds.validity) : "skipped";
}

// Histogram lines (bars relative to the values counted).
void histogram_lines(std::string& out, const QualityHistogram& h) {
  for (std::size_t b = 0; b < QualityHistogram::kBins; ++b) {
    const std::size_t width = h.values ? (h.bins[b] * 40 + h.values - 1) / h.values : 0;
    out += fmt::format("  {:>12} {:>9} {}\n", QualityHistogram::label(b), h.bins[b], std::string(width, '#'));
  }
}

// The summary section of mu (sj = false) or the scaled Jacobian (sj = true).
void quality_section(std::string& out, const CheckSummary& r, bool sj, std::size_t worst) {
  const QualitySummary& qs = sj ? r.sj : r.mu;
  const QualityCounts& qc = qs.counts;
  const char* name = sj ? "scaled Jacobian" : "mu";
  out += fmt::format("  {} ({}): computed {}, skipped {}, tolerance not met {}\n", name,
                     sj ? "min of det J / product of column norms, corner frames for simplices, prisms, pyramids"
                        : "min of sqrt(lambda_min / lambda_max) of W^T W, Paper V",
                     qc.computed, qc.skipped, qc.tolerance_not_met);
  for (const auto& [id, n] : qc.skipped_types) {
    const ElementType* t = find_element_type(id);
    out += fmt::format("  note: {} {} skipped for {}: type or order not supported\n", n, t ? t->name : "?", name);
  }
  const std::vector<WorstElement> wl = qs.worst.sorted();
  if (qs.histogram.values == 0 || wl.empty()) {
    out += "\n";
    return;
  }
  out += fmt::format("  {} lower bounds: min {:.6g} (element {}), mean {:.6g}\n", name, wl.front().quality.lower,
                     wl.front().tag, qs.lower_sum / static_cast<double>(qs.histogram.values));
  out += fmt::format("  histogram of the {} lower bounds\n", name);
  histogram_lines(out, qs.histogram);
  const std::size_t n = std::min(worst, wl.size());
  if (n > 0) {
    out += fmt::format("  worst {} elements by {}\n", n, name);
    out += fmt::format("  {:>10} {:<22} {:<13} {:>13} {:>13} {:>8}\n", "tag", "type", "validity", "lower", "upper", "subdiv");
    for (std::size_t k = 0; k < n; ++k) {
      const WorstElement& e = wl[k];
      out += fmt::format("  {:>10} {:<22} {:<13} {:>13.6g} {:>13.6g} {:>8}\n", e.tag, e.type->name,
                         validity_name(e.bounds.validity), e.quality.lower, e.quality.upper, e.quality.subdivisions);
    }
  }
  out += "\n";
}

// One element of the JSON "elements" array on one line, as nlohmann::json::dump() writes it
// (keys sorted, no spaces), straight into `out`: the DOM and its dump took 5 s for a million
// elements. One line per element instead of dump(1)'s layout (a line per value) makes the
// file a quarter smaller and lets line tools pick elements: 1M hexahedra, --measure
// jacobian 378 -> 278 MB, CLI 2.08-2.90 -> 2.01-2.19 s (three alternating runs); --measure
// all 670 -> 504 MB. Non-finite doubles are null, as nlohmann writes them; the others the
// shortest text that reads back to the same double.
void append_element_json(std::string& out, const ElementCheck& e, const DistortionBounds& d,
                         const QualityBounds& mu, const QualityBounds& sj) {
  auto it = std::back_inserter(out);
  const auto number = [&](double x) {
    if (std::isfinite(x))
      fmt::format_to(it, FMT_COMPILE("{}"), x);
    else
      out += "null";
  };
  const auto pair = [&](const char* key, double lo, double hi) {
    fmt::format_to(it, FMT_COMPILE("\"{}\":["), key);
    number(lo);
    out += ',';
    number(hi);
    out += "],";
  };
  const auto field = [&](const char* key, double x) {
    fmt::format_to(it, FMT_COMPILE("\"{}\":"), key);
    number(x);
    out += ',';
  };
  const auto quality = [&](const char* key, const QualityBounds& q) {
    if (std::isnan(q.lower)) return;
    fmt::format_to(it, FMT_COMPILE("\"{}\":{{\"lower\":"), key);
    number(q.lower);
    fmt::format_to(it, FMT_COMPILE(",\"subdivisions\":{},\"tolerance_met\":{},\"upper\":"), q.subdivisions,
                   q.tolerance_met);
    number(q.upper);
    out += "},";
  };
  out += '{';
  if (e.analysed) {
    const JacobianBounds& b = e.bounds;
    pair("distortion", d.lower, d.upper);
    fmt::format_to(it, FMT_COMPILE("\"exact\":{},"), b.exact);
    pair("jmax", b.jmax_lower, b.jmax_upper);
    pair("jmin", b.jmin_lower, b.jmin_upper);
    field("jmin_over_javg", e.jmin_over_javg());
    quality("mu", mu);
    field("ratio_lower", e.ratio_lower());
    quality("sj", sj);
    fmt::format_to(it, FMT_COMPILE("\"stage\":{},\"subdivisions\":{},"), b.stage, b.subdivisions);
  }
  fmt::format_to(it, FMT_COMPILE("\"tag\":{},\"type\":{},\"validity\":\"{}\"}}"), e.tag, e.type->gmsh_id,
                 answer(e));
}

// check_json's "summary" object.
nlohmann::json summary_json(const CheckSummary& r) {
  using nlohmann::json;
  json summary = {{"file", r.file},
                  {"measure", measure_name(r.measure)},
                  {"dimension", r.dimension},
                  {"planar", r.planar},
                  {"elements", r.elements},
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
  const auto first_tags = [](const WorstList& list) {
    json tags = json::array();
    const std::vector<WorstElement> w = list.sorted();
    for (std::size_t k = 0; k < std::min<std::size_t>(10, w.size()); ++k) tags.push_back(w[k].tag);
    return tags;
  };
  for (const auto& [key, qs, on] : {std::tuple{"mu", &r.mu, measures_mu(r.measure)},
                                    std::tuple{"scaled_jacobian", &r.sj, measures_scaled_jacobian(r.measure)}}) {
    if (!on) continue;
    const QualityCounts& qc = qs->counts;
    json q = {{"computed", qc.computed}, {"skipped", qc.skipped}, {"tolerance_not_met", qc.tolerance_not_met}};
    q["worst_tags"] = first_tags(qs->worst);
    summary[key] = q;
  }
  json stages = json::array();
  for (const StageRow& s : r.stages)
    stages.push_back({{"stage", s.name}, {"valid", s.valid}, {"invalid", s.invalid}, {"cpu_seconds", s.seconds}});
  summary["stages"] = stages;
  summary["worst_tags"] = first_tags(r.worst);
  return summary;
}

// One CSV row (check_csv).
void csv_row(std::string& out, const ElementCheck& e, const DistortionBounds& d, const QualityBounds& mu,
             const QualityBounds& sj) {
  const JacobianBounds& b = e.bounds;
  if (!e.analysed) {
    out += fmt::format("{},{},skipped,nan,nan,nan,nan,nan,0,nan,nan,nan,-1,0,nan,nan,nan,nan\n", e.tag, e.type->gmsh_id);
    return;
  }
  // Doubles printed shortest (fmt's {} reads back exactly, and prints nan and inf as such),
  // straight into `out`: a million rows in about 0.3 s instead of 2-3 s.
  fmt::format_to(std::back_inserter(out), FMT_COMPILE("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n"), e.tag,
                 e.type->gmsh_id, answer(e), num(b.jmin_lower), num(b.jmin_upper), num(b.jmax_lower),
                 num(b.jmax_upper), num(d.lower), b.subdivisions, num(d.upper), num(e.jmin_over_javg()),
                 num(e.ratio_lower()), b.stage, b.exact ? 1 : 0, num(mu.lower), num(mu.upper), num(sj.lower),
                 num(sj.upper));
}

// `text` with `pad` spaces after every line break (nesting a dump(1) one level deeper).
std::string indented(const std::string& text, const std::string& pad) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (char c : text) {
    out += c;
    if (c == '\n') out += pad;
  }
  return out;
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

std::string format_check_summary(const CheckSummary& r, std::size_t worst) {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line(fmt::format("[check] {}: {} elements of dimension {}{}, measure {}, {} thread{}, {:.3g} s",
                   r.file, r.elements, r.dimension,
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
  const bool by_distortion = measures_distortion(r.measure);
  line(fmt::format("  histogram of the {}", by_distortion ? "distortion lower bound (min J / J_straight)"
                                                          : "min J / max J lower bound"));
  histogram_lines(out, r.histogram);
  if (r.histogram.undefined) line(fmt::format("  {:>12} {:>9}", "undefined", r.histogram.undefined));
  line("");

  const std::vector<WorstElement> w = r.worst.sorted();
  const std::size_t n = std::min(worst, w.size());
  if (n > 0) {
    line(fmt::format("  worst {} elements", n));
    line(fmt::format("  {:>10} {:<22} {:<13} {:>13} {:>13} {:>11}", "tag", "type", "validity", "jmin_lower",
                     "jmin_upper", by_distortion ? "distortion" : "ratio"));
    for (std::size_t k = 0; k < n; ++k) {
      const WorstElement& e = w[k];
      line(fmt::format("  {:>10} {:<22} {:<13} {:>13.6g} {:>13.6g} {:>11.5g}", e.tag, e.type->name,
                       validity_name(e.bounds.validity), e.bounds.jmin_lower, e.bounds.jmin_upper, e.key));
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

std::string format_check_summary(const CheckReport& report, std::size_t worst) {
  return format_check_summary(summarize(report, worst), worst);
}

std::string check_csv_header() {
  return "tag,type,validity,jmin_lower,jmin_upper,jmax_lower,jmax_upper,distortion_lower,subdivisions,"
         "distortion_upper,jmin_over_javg,ratio_lower,stage,exact,mu_lower,mu_upper,sj_lower,sj_upper\n";
}

void append_check_csv_rows(std::string& out, const CheckBatch& b) {
  for (std::size_t i = 0; i < b.elements.size(); ++i) csv_row(out, b.elements[i], b.distortion_of(i), b.mu_of(i), b.sj_of(i));
}

std::string check_csv(const CheckReport& r) {
  std::string out = check_csv_header();
  for (std::size_t i = 0; i < r.elements.size(); ++i) csv_row(out, r.elements[i], r.distortion_of(i), r.mu_of(i), r.sj_of(i));
  return out;
}

std::string check_json(const CheckReport& r) {
  std::ostringstream out;
  CheckJsonWriter writer(out);
  CheckBatch all;
  all.elements = r.elements;
  all.distortion = r.distortion;
  all.mu = r.mu;
  all.sj = r.sj;
  writer.add(all);
  writer.finish(summarize(r, 10));
  return out.str();
}

// {"elements": [...], "summary": {...}} (keys sorted), one element at a time, each on a line
// of its own (append_element_json); the summary as json::dump(1) lays it out.
CheckJsonWriter::CheckJsonWriter(std::ostream& out) : out_(&out) { *out_ << "{\n \"elements\": ["; }

void CheckJsonWriter::add(const CheckBatch& b) {
  std::string text;
  for (std::size_t i = 0; i < b.elements.size(); ++i) {
    text += any_ ? ",\n  " : "\n  ";
    any_ = true;
    append_element_json(text, b.elements[i], b.distortion_of(i), b.mu_of(i), b.sj_of(i));
  }
  *out_ << text;
}

void CheckJsonWriter::finish(const CheckSummary& summary) {
  *out_ << (any_ ? "\n ]" : "]") << ",\n \"summary\": " << indented(summary_json(summary).dump(1), " ") << "\n}\n";
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

CheckFieldCollector::CheckFieldCollector(const Mesh& mesh, CheckMeasure measure) : measure_(measure) {
  const std::size_t n = mesh.num_elements();
  fields_ = {{"validity", {}}, {"jmin_lower", {}}, {"jmin_upper", {}}, {"ratio_lower", {}},
             {"distortion_lower", {}}, {"mu_lower", {}}, {"sj_lower", {}}};
  // mu_lower and sj_lower only when the measure computes them (as check_fields).
  if (!measures_scaled_jacobian(measure)) fields_.erase(fields_.begin() + 6);
  if (!measures_mu(measure)) fields_.erase(fields_.begin() + 5);
  for (auto& [name, values] : fields_) values.assign(n, NAN);
  const int dim = mesh.dimension();
  std::size_t first = 0, offset = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type->dim == dim) {
      runs_.push_back({first, b.size(), offset});
      first += b.size();
    }
    offset += b.size();
  }
}

void CheckFieldCollector::add(const CheckBatch& batch) {
  for (std::size_t i = 0; i < batch.elements.size(); ++i) {
    const ElementCheck& c = batch.elements[i];
    if (!c.analysed) continue;  // NaN everywhere, as initialised
    const std::size_t g = batch.first + i;
    // The run holding analysed element g: the last one starting at or before it.
    const auto run = std::prev(std::upper_bound(runs_.begin(), runs_.end(), g,
                                                [](std::size_t x, const Run& r) { return x < r.first; }));
    const std::size_t at = run->offset + (g - run->first);
    const double values[7] = {
        c.bounds.validity == Validity::valid ? 1.0 : c.bounds.validity == Validity::invalid ? -1.0 : 0.0,
        c.bounds.jmin_lower, c.bounds.jmin_upper, c.ratio_lower(), batch.distortion_of(i).lower,
        batch.mu_of(i).lower, batch.sj_of(i).lower};
    std::size_t f = 0;
    for (std::size_t k = 0; k < 7; ++k) {
      if ((k == 5 && !measures_mu(measure_)) || (k == 6 && !measures_scaled_jacobian(measure_))) continue;
      fields_[f++].second[at] = values[k];
    }
  }
}

std::vector<std::pair<std::string, std::vector<double>>> CheckFieldCollector::take() {
  return std::move(fields_);
}

}  // namespace quadval
