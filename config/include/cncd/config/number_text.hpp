// Numbers in messages, written one way across the project.
#pragma once

#include <string>

namespace cncd::config {

// "%.10g": short for round values, and enough digits to tell a value from its limit.
std::string format_number(double value);

}  // namespace cncd::config
