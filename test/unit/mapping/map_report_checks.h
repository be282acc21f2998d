// Reading a MapEvaluator report in the mapping tests: the mean error of one shape quantity of one
// class (e.g. "plane", "offset_m"); a quantity the report lacks fails the test.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "quadric_slam/eval/map_metrics.h"

namespace quadric_slam {
namespace test {

inline double meanError(const MapReport& report, const std::string& quadric_class,
                        const std::string& name) {
  for (const ShapeError& e : report.classes.at(quadric_class).mean_errors)
    if (e.name == name)
      return e.value;
  ADD_FAILURE() << "no " << name << " for " << quadric_class;
  return 1e9;
}

}  // namespace test
}  // namespace quadric_slam
