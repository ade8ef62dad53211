// cncd-fleet's command line (docs/fleet.md): where the page listens, the broker and its
// credentials (given, or [TELEMETRY]'s of a machine INI), the topic pattern and the limits.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "machine_table.hpp"
#include "subscriber.hpp"

namespace cncd::fleet {

struct Options {
  std::string listen_address = "127.0.0.1";
  int listen_port = 8090;
  std::filesystem::path www;  // empty: <bin>/../share/cncd/fleet-www
  BrokerOptions broker{"127.0.0.1", 1883, "", "", "", 5};
  std::string pattern = "cncd/+";
  TableLimits limits;
  std::size_t max_clients = 64;  // WebSockets at once
  int push_ms = 50;              // changes go to the browsers at most this often
  std::vector<std::string> allowed_origins;
  std::string log_level = "info";
};

struct Parsed {
  std::optional<Options> options;  // none: exit with `status` after printing `message`
  int status = 0;
  std::string message;
};

// The arguments after the program's name.
Parsed parse_options(const std::vector<std::string>& args);
std::string usage();

}  // namespace cncd::fleet
