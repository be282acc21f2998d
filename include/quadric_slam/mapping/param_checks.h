// Range checks of a Params struct's fields, with one message format for the mapping components:
// "<Owner>::Params::<field> must be in <range>".
#pragma once

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

 private:
  const char* owner_;
};

}  // namespace quadric_slam
