// The plcfi subcommands. Each takes the arguments after its name and returns the exit status.
#pragma once

#include <string>
#include <vector>

namespace plcfi::cli {

int cmd_check(const std::vector<std::string>& args);
int cmd_run(const std::vector<std::string>& args);
int cmd_test(const std::vector<std::string>& args);
int cmd_disasm(const std::vector<std::string>& args);
int cmd_sim(const std::vector<std::string>& args);
int cmd_edtl(const std::vector<std::string>& args);
int cmd_generate(const std::vector<std::string>& args);
int cmd_campaign(const std::vector<std::string>& args);
int cmd_plant_server(const std::vector<std::string>& args);

}  // namespace plcfi::cli
