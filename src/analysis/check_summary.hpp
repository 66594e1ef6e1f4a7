#pragma once
// Building a CheckSummary batch by batch (check_mesh_streamed). Internal to src/analysis.
#include <string>

#include "quadval/check_report.hpp"

namespace quadval {

/// A summary with no elements yet, keeping max(worst, 10) worst elements per list.
CheckSummary empty_summary(const std::string& file, CheckMeasure measure, std::size_t worst);

/// Adds the histograms and worst-list candidates of the batch's elements [from, to). The
/// result does not depend on the order of the calls (integer counts, ordered heaps), so
/// threads may each fill their own summary and merge_summary them afterwards.
void add_elements(CheckSummary& summary, const CheckBatch& batch, std::size_t from, std::size_t to);

/// Adds the batch's mu and scaled-Jacobian lower bounds to their sums: batches must come in
/// element order (a floating-point sum depends on it).
void add_sums(CheckSummary& summary, const CheckBatch& batch);

/// Adds `part`'s histograms and worst lists to `into` (counts, stages, sums untouched).
void merge_summary(CheckSummary& into, const CheckSummary& part);

}  // namespace quadval
