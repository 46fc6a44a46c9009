// The HTML report's model filled from a finished campaign (plcfi campaign --html).
#pragma once

#include <string>

#include "campaign/driver.hpp"
#include "campaign/generate.hpp"
#include "report/html.hpp"

namespace plcfi::cli {

// The rows are by case and path (as the text summary), then the cases NOT REACHED and NOT
// TESTED. The VCDs are looked up in out_dir; with vcd false the waveforms are left out
// with a note saying why.
report::HtmlReport html_campaign_model(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res,
                                       const std::string& out_dir, bool vcd);

// Creates DIR and checks that a report can be written there (false, "DIR: reason").
bool html_dir_writable(const std::string& dir, std::string* err);

}  // namespace plcfi::cli
