// What the Modbus bus's files share: the libmodbus context behind the bus's opaque pointer,
// and which errors are a drive's exception replies.
#pragma once

#include <modbus/modbus.h>

namespace cncd::drivers::modbus_detail {

inline modbus_t* as_ctx(void* p) {
  return static_cast<modbus_t*>(p);
}

// An exception reply: the drive answered, the request was wrong; the link itself is fine.
inline bool is_exception(int error) {
  return error >= EMBXILFUN && error <= EMBXGTAR;
}

}  // namespace cncd::drivers::modbus_detail
