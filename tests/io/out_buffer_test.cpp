// The writers' fast pieces (io/out_buffer.hpp): integer() and real() write exactly what
// text("{}", v) writes, the shortest round-trip form, so that files keep their bytes; and
// records() on several threads writes what the plain loop writes, and fails where it fails.
#include <gtest/gtest.h>
#include <omp.h>

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/out_buffer.hpp"

namespace quadval::io {
namespace {

template <class Write>
std::string written(Write write) {
  std::ostringstream out;
  {
    OutBuffer buffer(out);
    write(buffer);
    buffer.flush();
  }
  return out.str();
}

TEST(OutBuffer, RealWritesWhatTheFormatStringWrites) {
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                -1.0,
                                0.1,
                                1e-7,
                                -9.999999994736442e-08,
                                100000.0,
                                1e16,
                                1e22,
                                123456789012345678.0,
                                5e-324,
                                2.2250738585072014e-308,
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::lowest(),
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::quiet_NaN()};
  std::mt19937_64 rng(7);
  for (int i = 0; i < 20000; ++i) {
    const double v = std::bit_cast<double>(rng());  // any bit pattern: every exponent
    values.push_back(v);
    values.push_back(std::ldexp(static_cast<double>(rng() % 2000001) - 1e6, -static_cast<int>(rng() % 40)));
  }
  const std::string got = written([&](OutBuffer& b) {
    for (double v : values) {
      b.real(v);
      b.put('\n');
    }
  });
  std::string want;
  for (double v : values) want += fmt::format("{}\n", v);
  EXPECT_EQ(got, want);
}

TEST(OutBuffer, IntegerWritesWhatTheFormatStringWrites) {
  const std::string got = written([](OutBuffer& b) {
    b.integer(std::uint64_t{0});
    b.put(' ');
    b.integer(std::numeric_limits<std::uint64_t>::max());
    b.put(' ');
    b.integer(std::numeric_limits<std::int64_t>::min());
    b.put(' ');
    b.integer(std::int32_t{-42});
    b.put(' ');
    b.integer(std::numeric_limits<std::int32_t>::min());
  });
  EXPECT_EQ(got, fmt::format("{} {} {} {} {}", std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max(),
                             std::numeric_limits<std::int64_t>::min(), -42, std::numeric_limits<std::int32_t>::min()));
}

// More than the 4 MiB the buffer holds before it flushes: nothing lost or reordered.
TEST(OutBuffer, LongOutputKeepsItsOrderAcrossFlushes) {
  constexpr std::uint64_t kCount = 1'000'000;
  const std::string got = written([](OutBuffer& b) {
    for (std::uint64_t i = 0; i < kCount; ++i) {
      b.integer(i);
      b.put('\n');
    }
  });
  ASSERT_GT(got.size(), std::size_t{1} << 22);
  std::istringstream in(got);
  std::uint64_t expected = 0, value = 0;
  while (in >> value) ASSERT_EQ(value, expected++);
  EXPECT_EQ(expected, kCount);
}

// Record i: "i x\n" with an awkward double x, or text of varying length.
void record(OutBuffer& b, std::size_t i) {
  b.integer(static_cast<std::uint64_t>(i));
  b.put(' ');
  if (i % 7 == 0) {
    b.text("{}", std::string(i % 23, 'a'));
  } else {
    b.real(std::ldexp(static_cast<double>(i) * 0.1, static_cast<int>(i % 60) - 30));
  }
  b.put('\n');
}

TEST(OutBuffer, RecordsWriteWhatThePlainLoopWrites) {
  const int threads = omp_get_max_threads();
  // Below the parallel threshold, just above, several rounds of pieces, a ragged last round.
  for (std::size_t count : {std::size_t{0}, std::size_t{1000}, std::size_t{40000}, std::size_t{300007}}) {
    const std::string want = written([&](OutBuffer& b) {
      b.text("head\n");
      for (std::size_t i = 0; i < count; ++i) record(b, i);
      b.text("tail\n");
    });
    for (int t : {1, 2, 3}) {
      omp_set_num_threads(t);
      const std::string got = written([&](OutBuffer& b) {
        b.text("head\n");
        b.records(count, record);
        b.text("tail\n");
      });
      EXPECT_EQ(got, want) << count << " records, " << t << " threads";
    }
  }
  omp_set_num_threads(threads);
}

TEST(OutBuffer, RecordsRethrowTheFirstFailureInOrder) {
  const int threads = omp_get_max_threads();
  for (int t : {1, 2}) {
    omp_set_num_threads(t);
    std::ostringstream out;
    OutBuffer b(out);
    try {
      b.records(200000, [](OutBuffer& o, std::size_t i) {
        if (i == 150001 || i == 70003) throw std::runtime_error(fmt::format("record {}", i));
        record(o, i);
      });
      ADD_FAILURE() << "no exception, " << t << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "record 70003") << t << " threads";
    }
  }
  omp_set_num_threads(threads);
}

}  // namespace
}  // namespace quadval::io
