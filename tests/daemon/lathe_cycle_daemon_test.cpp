// A G71 roughing cycle on the sim lathe (config/examples/sim_lathe.ini), run by the real daemon:
// it runs to done, every position the machine passes lies on the path LinuxCNC's rs274 prints
// for the program (tests/golden/lathe_g71_sim_lathe, expected.canon), and every move's end the
// status shows is one of rs274's end points, in rs274's order.
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

struct Point {
  double x = 0, z = 0;
};

// A line (or, with `arc`, an arc about c) from a to b in the XZ plane.
struct Piece {
  Point a, b;
  bool arc = false;
  Point c;
};

// rs274's moves, from `start`: STRAIGHT_TRAVERSE/STRAIGHT_FEED(x, y, z, ...) and, in the XZ
// plane, ARC_FEED(z end, x end, z center, x center, rotation, ...).
std::vector<Piece> canon_path(const std::string& canon, Point start) {
  std::vector<Piece> path;
  std::istringstream in(canon);
  std::string line;
  Point at = start;
  while (std::getline(in, line)) {
    Piece piece;
    piece.a = at;
    double x = 0, y = 0, z = 0, cx = 0, cz = 0;
    int rotation = 0;
    if (std::sscanf(line.c_str(), "STRAIGHT_TRAVERSE(%lf, %lf, %lf", &x, &y, &z) == 3 ||
        std::sscanf(line.c_str(), "STRAIGHT_FEED(%lf, %lf, %lf", &x, &y, &z) == 3) {
      piece.b = {x, z};
    } else if (std::sscanf(line.c_str(), "ARC_FEED(%lf, %lf, %lf, %lf, %d", &z, &x, &cz, &cx,
                           &rotation) == 5) {
      piece.b = {x, z};
      piece.arc = true;
      piece.c = {cx, cz};
    } else {
      continue;
    }
    path.push_back(piece);
    at = piece.b;
  }
  return path;
}

double distance_to(const Piece& piece, Point p) {
  if (piece.arc) {
    const double r = std::hypot(piece.a.x - piece.c.x, piece.a.z - piece.c.z);
    return std::fabs(std::hypot(p.x - piece.c.x, p.z - piece.c.z) - r);
  }
  const double dx = piece.b.x - piece.a.x, dz = piece.b.z - piece.a.z;
  const double len2 = dx * dx + dz * dz;
  double t = len2 > 0 ? ((p.x - piece.a.x) * dx + (p.z - piece.a.z) * dz) / len2 : 0.0;
  t = std::fmax(0.0, std::fmin(1.0, t));
  return std::hypot(p.x - (piece.a.x + t * dx), p.z - (piece.a.z + t * dz));
}

bool near(Point p, Point q, double tolerance) {
  return std::fabs(p.x - q.x) <= tolerance && std::fabs(p.z - q.z) <= tolerance;
}

class LatheCycleTest : public MachineTest {
 protected:
  std::string example() const override { return "sim_lathe"; }
};

TEST_F(LatheCycleTest, G71RoughingRunsToDoneAlongRs274sPath) {
  ready_machine();
  const std::string golden = std::string(CNCD_SOURCE_DIR) + "/tests/golden/lathe_g71_sim_lathe";
  json s = status();
  const Point home{s["position"]["commanded"]["x"].get<double>(),
                   s["position"]["commanded"]["z"].get<double>()};
  const std::vector<Piece> path = canon_path(slurp(golden + "/expected.canon"), home);
  ASSERT_GT(path.size(), 40u);
  // rs274's end points in order, each once where it repeats itself (moves of no length).
  std::vector<Point> ends;
  for (const Piece& piece : path) {
    if (ends.empty() || !near(ends.back(), piece.b, 1e-9)) ends.push_back(piece.b);
  }

  start_program("g71.ngc", slurp(golden + "/program.ngc"), "program.run");
  std::vector<Point> samples;
  std::vector<Point> move_ends;
  s = wait_until([&](const json& st) {
    const Point p{st["position"]["commanded"]["x"].get<double>(),
                  st["position"]["commanded"]["z"].get<double>()};
    samples.push_back(p);
    if (st["motion"] == "moving") {
      const Point end{p.x + st["axes_to_go"]["x"].get<double>(),
                      p.z + st["axes_to_go"]["z"].get<double>()};
      if (move_ends.empty() || !near(move_ends.back(), end, 1e-6)) move_ends.push_back(end);
    }
    return st["exec"] == "idle";
  });
  EXPECT_EQ(s["program"]["result"], "done") << s["program"].dump();
  const Point last{s["position"]["commanded"]["x"].get<double>(),
                   s["position"]["commanded"]["z"].get<double>()};
  EXPECT_TRUE(near(last, ends.back(), 1e-4)) << last.x << " " << last.z;

  // G61: no corner is rounded, so the machine never leaves rs274's path (printed to 0.1 um).
  for (const Point& p : samples) {
    double best = 1e9;
    for (const Piece& piece : path)
      best = std::fmin(best, distance_to(piece, p));
    EXPECT_LT(best, 2e-4) << "X" << p.x << " Z" << p.z << " is off rs274's path";
  }
  // Every move the status showed under way ends where one of rs274's moves ends, in order.
  std::size_t next = 0;
  for (const Point& end : move_ends) {
    while (next < ends.size() && !near(ends[next], end, 1e-4))
      ++next;
    ASSERT_LT(next, ends.size()) << "a move to X" << end.x << " Z" << end.z
                                 << " that rs274 does not make here";
  }
  // The passes take long enough to be seen: most of the moves were.
  EXPECT_GE(move_ends.size(), ends.size() / 3) << move_ends.size() << " of " << ends.size();
}

}  // namespace
}  // namespace cncd::test
