// Fuzz target: the campaign file reader (load_campaign), with the stamping campaign's TSD,
// FMEA and fault classes beside it, so references between the files are checked too.
#include <cstdint>
#include <string>

#include "campaign/spec.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  plcfi::fuzz::copy_into_temp("faults/campaigns/stamping/tsd.yaml", "tsd.yaml");
  plcfi::fuzz::copy_into_temp("faults/campaigns/stamping/fmea.csv", "fmea.csv");
  plcfi::fuzz::copy_into_temp("faults/campaigns/stamping/fault_classes.yaml", "fault_classes.yaml");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("campaign.yaml", fuzz::as_text(data, size));
  campaign::Campaign out;
  std::string err;
  if (campaign::load_campaign(path, &out, &err)) (void)campaign::check_references(out, &err);
  return 0;
}
