// CNCD_RT marks the declaration of a function the servo period calls (ServoLoop::cycle() and
// everything below it, the drivers' read and write included). Such a function allocates
// nothing, takes no lock, logs nothing, does no I/O beyond a driver's own register or GPIO
// access, formats no text and throws nothing: it is noexcept, which
// tests/motion/rt_marker_test.cpp checks for every marked declaration. The mark itself
// expands to nothing.
#pragma once

#define CNCD_RT
