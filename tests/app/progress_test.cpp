// app/progress.h: the estimate of the time left on a fake clock, and what reaches the terminal when.
#include "app/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace pvrr::app {
namespace {

// What a Progress writes, captured in memory.
class Captured {
 public:
  Captured() : file_(open_memstream(&buf_, &size_)) {}
  ~Captured() {
    std::fclose(file_);
    std::free(buf_);
  }
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    return std::string(buf_, size_);
  }

 private:
  char* buf_ = nullptr;
  size_t size_ = 0;
  std::FILE* file_;
};

TEST(Progress, TimeLeftIsTheElapsedTimeScaledByWhatIsLeftOverWhatIsDone) {
  double now = 100.0;
  Progress p("sweep", 12, nullptr, [&] { return now; });
  EXPECT_FALSE(p.secondsLeft(0).has_value());  // nothing done: no rate yet
  now = 110.0;
  // 3 of 12 in 10 s: 9 left at 10/3 s each.
  ASSERT_TRUE(p.secondsLeft(3).has_value());
  EXPECT_DOUBLE_EQ(*p.secondsLeft(3), 30.0);
  now = 140.0;
  EXPECT_DOUBLE_EQ(*p.secondsLeft(8), 40.0 * 4 / 8);
  EXPECT_DOUBLE_EQ(*p.secondsLeft(12), 0.0);
  EXPECT_DOUBLE_EQ(*p.secondsLeft(13), 0.0);  // never negative
  // A fraction (total 1), as the reference tracer reports it: 25 % in 2 s leaves 6 s.
  now = 0.0;
  Progress f("ray tracing", 1.0, nullptr, [&] { return now; });
  now = 2.0;
  EXPECT_DOUBLE_EQ(*f.secondsLeft(0.25), 6.0);
}

TEST(Progress, LineShowsCountShareElapsedAndEstimate) {
  double now = 0.0;
  Progress p("sweep", 12, nullptr, [&] { return now; });
  now = 10.0;
  EXPECT_EQ(p.line(3), "sweep: [#####               ] 3/12   25%  10 s, about 30 s left");
  EXPECT_EQ(p.line(0), "sweep: [                    ] 0/12    0%  10 s, estimating");
  Progress f("ray tracing", 1.0, nullptr, [&] { return now; });
  now = 20.0;
  EXPECT_EQ(f.line(0.5), "ray tracing: [##########          ]  50%  10 s, about 10 s left");
  EXPECT_EQ(Progress::duration(185), "3 min 05 s");
  EXPECT_EQ(Progress::duration(3725), "1 h 02 min");
  EXPECT_EQ(Progress::duration(-3), "0 s");
}

TEST(Progress, QuietDuringTheFirstSecondThenRedrawnAtMostFourTimesASecond) {
  Captured out;
  double now = 0.0;
  {
    Progress p("compare", 4, out.file(), [&] { return now; });
    now = 0.5;
    p.update(1);
    EXPECT_EQ(out.text(), "");  // work that ends within a second shows nothing
    now = 1.2;
    p.update(2);
    const std::string first = out.text();
    EXPECT_NE(first.find("\rcompare: ["), std::string::npos) << first;
    EXPECT_NE(first.find("2/4"), std::string::npos) << first;
    now = 1.3;
    p.update(3);
    EXPECT_EQ(out.text(), first);  // within kRedrawSeconds of the last line
    now = 1.35;
    p.update(4);  // the last unit is always drawn
    EXPECT_NE(out.text().find("4/4"), std::string::npos);
  }  // the destructor ends the line
  const std::string all = out.text();
  EXPECT_NE(all.find("compare: done in 1 s"), std::string::npos) << all;
  EXPECT_EQ(all.back(), '\n');
}

TEST(Progress, NothingIsWrittenWhenNotShown) {
  Captured out;
  double now = 0.0;
  {
    Progress p("fov", 3, out.file(), [&] { return now; });
    now = 0.4;
    p.update(3);
  }
  EXPECT_EQ(out.text(), "");
}

}  // namespace
}  // namespace pvrr::app

namespace pvrr::app {
namespace {

TEST(Progress, AnInnerProgressStaysQuiet) {
  Captured out;
  double now = 0.0;
  Progress outer("sweep", 2, out.file(), [&] { return now; });
  {
    Progress inner("ray tracing", 1.0, out.file(), [&] { return now; });
    now = 5.0;
    inner.update(1.0);
  }
  EXPECT_EQ(out.text(), "");
  outer.update(1);
  EXPECT_NE(out.text().find("sweep: ["), std::string::npos);
}

}  // namespace
}  // namespace pvrr::app
