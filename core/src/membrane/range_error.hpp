// The membrane layer's one way to refuse a setting: std::invalid_argument saying
// "<owner>: <field> = <value> is out of range (<range>)" (ARCHITECTURE.md's error rule).
#pragma once

#include <sstream>
#include <stdexcept>

namespace conform::membrane {

/// A checker for one owner ("skin material", "membrane solver", ...): check(ok, field, value,
/// range) throws when !ok.
class RangeCheck {
 public:
  explicit RangeCheck(const char* owner) : owner_(owner) {}
  void operator()(bool ok, const char* field, double value, const char* range) const {
    if (ok) return;
    std::ostringstream out;
    out << owner_ << ": " << field << " = " << value << " is out of range (" << range << ")";
    throw std::invalid_argument(out.str());
  }

 private:
  const char* owner_;
};

}  // namespace conform::membrane
