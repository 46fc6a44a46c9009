// The HTML report's model filled from a finished campaign (plcfi campaign --html, plcfi
// mutate --html).
#pragma once

#include <string>

#include "campaign/driver.hpp"
#include "campaign/generate.hpp"
#include "report/html.hpp"

namespace plcfi::report {

// The rows are by case and path (as the text summary), then the cases NOT REACHED and NOT
// TESTED. The VCDs are looked up in out_dir; with vcd false the waveforms are left out
// with a note saying why.
HtmlReport campaign_html_model(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res,
                               const std::string& out_dir, bool vcd);

}  // namespace plcfi::report
