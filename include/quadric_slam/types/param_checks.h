// Range checks of a Params struct's fields, with one message format for every component:
// "<Owner>::<field> must be in <range>[, got <value>]".
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace quadric_slam {

class ParamRangeCheck {
 public:
  // owner: e.g. "QuadricMapper::Params".
  explicit ParamRangeCheck(const char* owner) : owner_(owner) {}

  // Throws std::invalid_argument naming the field and its allowed range unless ok.
  void operator()(bool ok, const char* field, const char* range) const {
    if (!ok)
      throw std::invalid_argument(std::string(owner_) + "::" + field + " must be in " + range);
  }
  // The same, naming the value given as well.
  void operator()(bool ok, const char* field, const char* range, double value) const {
    if (!ok)
      fail(field, range, value);
  }
  [[noreturn]] void fail(const char* field, const char* range, double value) const {
    std::ostringstream why;
    why << owner_ << "::" << field << " must be in " << range << ", got " << value;
    throw std::invalid_argument(why.str());
  }

 private:
  const char* owner_;
};

}  // namespace quadric_slam
