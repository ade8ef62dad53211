// Cutter radius compensation as LinuxCNC's interpreter does it: each move in the plane is
// offset by the tool radius and held back until the next move shows the corner between them
// (an inside corner trims both, an outside one gets an arc around it), then sent.
#pragma once

#include "interp_state.hpp"

namespace cncd::interp {

struct Interpreter::Impl::Comp {
  // G40, G41, G42, G41.1, G42.1 (ten times the code).
  static void comp_mode(Impl& s, int code);
  // A straight move or an arc of the block while compensation is active.
  static void comp_straight(Impl& s, StraightKind kind, const Pose& end);
  static void comp_arc(Impl& s, bool clockwise, const Pose& end, int turns);
  // Where the block's move starts in its words' eyes: the programmed point, not the tool's.
  static Pose comp_program_start(const Impl& s);
  // M0, M1, M2, M30, M60: the held-back moves go out as they are.
  static void comp_flush(Impl& s);
  // Queues `command` behind held-back moves when it is one LinuxCNC holds back; true if so.
  static bool comp_hold_back(Impl& s, const CanonCommand& command);
  // G20/G21 with moves held back: they are scaled to the new units.
  static void comp_scale(Impl& s, double factor);
  // Moves the plane end of every held-back move to `to` (the corner the next move found),
  // refusing one the change would reverse or carry past its arc (the tool would gouge), and
  // sends them.
  static void comp_move_end_and_flush(Impl& s, PlanePoint to);
  // Sends the held-back commands in order.
  static void comp_dequeue(Impl& s);

 private:
  static const QueuedCanon* front(const Impl& s);
  static void comp_off(Impl& s);
  static void comp_on(Impl& s, int code);
  static void set_start(Impl& s, PlanePoint p);
  static void enqueue_straight(Impl& s, StraightKind kind, PlanePoint dir, const Pose& end);
  static void enqueue_arc(Impl& s, double sweep, PlanePoint end, PlanePoint center, int turn,
                          const Pose& end_pose);
  static void set_current(Impl& s, const Pose& end, PlanePoint tool);
  static void entry_straight(Impl& s, StraightKind kind, const Pose& end);
  static void entry_arc(Impl& s, bool clockwise, const Pose& end, int turns);
  static PlanePoint arc_line_corner(Impl& s, const ArcFeed& prev, PlanePoint op, PlanePoint p);
};

}  // namespace cncd::interp
