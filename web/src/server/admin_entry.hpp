// Start-up steps of cncd-web besides the network: the admin commands, and the checks and
// loading done before serving.
#pragma once

#include <string>
#include <vector>

#include "app.hpp"

namespace cncd::web {

// `cncd-web --ini INI user|key ...`: the exit status.
int run_admin(const std::vector<std::string>& args, const config::WebConfig& web);

// Loads the users, checks the program directory and the page's files, sets up TLS when
// [WEB] TLS_CERT/TLS_KEY are given. "" or why cncd-web cannot serve.
std::string prepare(App& app);

}  // namespace cncd::web
