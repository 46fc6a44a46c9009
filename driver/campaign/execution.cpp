// Names of the execution records' enumerations.
#include "execution.hpp"

namespace plcfi::campaign {

const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::Pass: return "PASS";
    case Outcome::Fail: return "FAIL";
    case Outcome::NotReached: return "NOT REACHED";
  }
  return "?";
}

}  // namespace plcfi::campaign
