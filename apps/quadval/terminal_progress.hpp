#pragma once
// One progress line on standard error, rewritten in place, for stages that run longer than a
// second, and only when standard error is a terminal (never in files or pipes).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include <fmt/core.h>

namespace quadval::cli {

class TerminalProgress {
 public:
  explicit TerminalProgress(bool wanted) : enabled_(wanted && isatty(STDERR_FILENO) != 0) {}
  ~TerminalProgress() { end_line(); }
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  /// Starts timing a stage: its line appears once it has run for a second.
  void start() { start_ = Clock::now(); }
  /// "\r[stage] text (percent)" once the stage has run for a second, at most ten times a
  /// second.
  void show(const std::string& stage, const std::string& text, double done, double total) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - start_).count() < 1.0 ||
        std::chrono::duration<double>(now - last_).count() < 0.1)
      return;
    last_ = now;
    fmt::print(stderr, "\r[{}] {} ({:.0f}%)", stage, text, total > 0 ? 100.0 * done / total : 0.0);
    std::fflush(stderr);
    shown_ = true;
  }
  /// Ends a shown line, so that the next message starts on a line of its own.
  void end_line() {
    if (shown_) fmt::print(stderr, "\n");
    shown_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  bool shown_ = false;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_{};
};

/// Blossom's progress (RecombineOptions::matching_progress) on `line`.
inline auto matching_progress_on(TerminalProgress& line) {
  return [&line](std::uint32_t paired, std::uint32_t unpaired_at_start) {
    line.show("blossom",
              fmt::format("{} of the {} triangles left free by the greedy start paired", paired,
                          unpaired_at_start),
              paired, unpaired_at_start);
  };
}

}  // namespace quadval::cli
