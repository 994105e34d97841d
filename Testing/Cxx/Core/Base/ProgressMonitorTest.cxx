#include <gtest/gtest.h>

#include "Base/ProgressMonitor.h"

TEST(ProgressMonitor, ForwardsClampedReportsAndSeesCancel) {
  std::atomic<bool> cancel{false};
  std::vector<fct::ProgressUpdate> seen;
  fct::ProgressMonitor monitor([&](const fct::ProgressUpdate& u) { seen.push_back(u); }, &cancel);
  monitor.report("stage 1", 1.7, "almost");
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].stage, "stage 1");
  EXPECT_DOUBLE_EQ(seen[0].fraction, 1.0);
  EXPECT_FALSE(monitor.cancelled());
  cancel = true;
  EXPECT_TRUE(monitor.cancelled());
}

TEST(ProgressMonitor, DefaultMonitorIsSilentAndNeverCancelled) {
  fct::ProgressMonitor monitor;
  monitor.report("anything", -3.0);
  EXPECT_FALSE(monitor.cancelled());
}
