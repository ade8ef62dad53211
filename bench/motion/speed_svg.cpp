#include "speed_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

namespace cncd::bench {
namespace {

// Time from the curve's first point to each of its points (ds over the mean speed).
std::vector<double> times(const SpeedCurve& c) {
  std::vector<double> t(c.s.size(), 0.0);
  for (std::size_t k = 1; k < c.s.size(); ++k) {
    const double ds = c.s[k] - c.s[k - 1], sum = c.v[k] + c.v[k - 1];
    t[k] = t[k - 1] + (ds > 0 && sum > 0 ? 2 * ds / sum : 0.0);
  }
  return t;
}

// The time at s, linear between points; the ends' outside them.
double time_at(const SpeedCurve& c, const std::vector<double>& t, double s) {
  const auto it = std::upper_bound(c.s.begin(), c.s.end(), s);
  if (it == c.s.begin()) return t.front();
  if (it == c.s.end()) return t.back();
  const auto k = static_cast<std::size_t>(std::distance(c.s.begin(), it));
  const double ds = c.s[k] - c.s[k - 1];
  return t[k - 1] + (t[k] - t[k - 1]) * (s - c.s[k - 1]) / ds;
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", std::abs(value) < 1e-9 ? 0.0 : value);
  return text;
}

std::string fixed(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", value);
  return text;
}

// Text as SVG character data: a program's name may hold <, & or quotes.
std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int most) {
  std::vector<double> out;
  if (!(hi > lo) || most < 2) return out;
  const double raw = (hi - lo) / (most - 1);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * power;
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * power >= raw * (1 - 1e-9)) {
      step = m * power;
      break;
    }
  }
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1)
    out.push_back(k * step);
  return out;
}

Window slowest_window(const SpeedCurve& slow, const SpeedCurve& fast, double width, double step) {
  if (slow.s.size() < 2 || fast.s.size() < 2 || fast.s.back() - fast.s.front() <= width ||
      step <= 0)
    return {0, width};
  const auto ts = times(slow), tf = times(fast);
  Window best{fast.s.front(), fast.s.front() + width};
  double most = -1;
  for (double from = fast.s.front(); from + width <= fast.s.back(); from += step) {
    const double lost = (time_at(slow, ts, from + width) - time_at(slow, ts, from)) -
                        (time_at(fast, tf, from + width) - time_at(fast, tf, from));
    if (lost > most) {
      most = lost;
      best = {from, from + width};
    }
  }
  return best;
}

std::string speed_svg(const std::vector<SpeedCurve>& curves, Window window,
                      const std::string& title, int width, int height) {
  const double left = 70, right = 20, top = 50, bottom = 55;
  const double w = width - left - right, h = height - top - bottom;
  double v_max = 0;
  for (const auto& c : curves)
    if (c.scales)
      for (std::size_t k = 0; k < c.s.size(); ++k)
        if (c.s[k] >= window.from && c.s[k] <= window.to) v_max = std::max(v_max, c.v[k]);
  // Headroom above the fastest point for the legend.
  const auto v_ticks = nice_ticks(0, v_max > 0 ? v_max * 1.35 : 1, 7);
  const double v_top = v_ticks.size() > 1 ? v_ticks.back() + (v_ticks[1] - v_ticks[0]) : 1;
  const double span = window.to > window.from ? window.to - window.from : 1;
  const auto x = [&](double s) { return left + (s - window.from) / span * w; };
  const auto y = [&](double v) { return top + h - v / v_top * h; };
  std::string out;
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) +
         "\" height=\"" + std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) +
         " " + std::to_string(height) +
         "\" font-family=\"sans-serif\" font-size=\"13\">\n"
         "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
         "<clipPath id=\"plot\"><rect x=\"" +
         fixed(left) + "\" y=\"" + fixed(top) + "\" width=\"" + fixed(w) + "\" height=\"" +
         fixed(h) + "\"/></clipPath>\n";
  out += "<text x=\"" + fixed(left + w / 2) +
         "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" + escaped(title) + "</text>\n";
  for (double s : nice_ticks(window.from, window.to, 11)) {
    out += "<line x1=\"" + fixed(x(s)) + "\" y1=\"" + fixed(top) + "\" x2=\"" + fixed(x(s)) +
           "\" y2=\"" + fixed(top + h + 5) + "\" stroke=\"#ddd\"/>\n";
    out += "<text x=\"" + fixed(x(s)) + "\" y=\"" + fixed(top + h + 20) +
           "\" text-anchor=\"middle\">" + number(s) + "</text>\n";
  }
  for (double v : v_ticks) {
    out += "<line x1=\"" + fixed(left - 5) + "\" y1=\"" + fixed(y(v)) + "\" x2=\"" +
           fixed(left + w) + "\" y2=\"" + fixed(y(v)) + "\" stroke=\"#ddd\"/>\n";
    out += "<text x=\"" + fixed(left - 9) + "\" y=\"" + fixed(y(v) + 4) +
           "\" text-anchor=\"end\">" + number(v) + "</text>\n";
  }
  out += "<rect x=\"" + fixed(left) + "\" y=\"" + fixed(top) + "\" width=\"" + fixed(w) +
         "\" height=\"" + fixed(h) + "\" fill=\"none\" stroke=\"black\"/>\n";
  out += "<text x=\"" + fixed(left + w / 2) + "\" y=\"" + fixed(height - 12.0) +
         "\" text-anchor=\"middle\">path length s (mm)</text>\n";
  out += "<text transform=\"translate(18 " + fixed(top + h / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">path speed (mm/s)</text>\n";
  for (const auto& c : curves) {
    out += "<polyline clip-path=\"url(#plot)\" fill=\"none\" stroke=\"" + c.colour +
           "\" stroke-width=\"" + number(c.width) + "\" stroke-linejoin=\"round\"" +
           (c.dashed ? " stroke-dasharray=\"6 4\"" : "") + " points=\"";
    for (std::size_t k = 0; k < c.s.size(); ++k) {
      const bool near =
          (k + 1 < c.s.size() && c.s[k + 1] >= window.from) && (k == 0 || c.s[k - 1] <= window.to);
      if (near) out += fixed(x(c.s[k])) + "," + fixed(y(c.v[k])) + " ";
    }
    out += "\"/>\n";
  }
  std::size_t longest = 0;
  for (const auto& c : curves)
    longest = std::max(longest, c.label.size());
  const double box = 60 + 7.2 * static_cast<double>(longest);  // 13 px sans-serif
  const double lx = left + w - box - 10, ly = top + 10;
  out += "<rect x=\"" + fixed(lx) + "\" y=\"" + fixed(ly) + "\" width=\"" + fixed(box) +
         "\" height=\"" + fixed(10 + 20.0 * static_cast<double>(curves.size())) +
         "\" fill=\"white\" fill-opacity=\"0.9\" stroke=\"#999\"/>\n";
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const double yy = ly + 18 + 20.0 * static_cast<double>(k);
    out += "<line x1=\"" + fixed(lx + 10) + "\" y1=\"" + fixed(yy - 4) + "\" x2=\"" +
           fixed(lx + 40) + "\" y2=\"" + fixed(yy - 4) + "\" stroke=\"" + curves[k].colour +
           "\" stroke-width=\"" + number(curves[k].width + 0.5) + "\"" +
           (curves[k].dashed ? " stroke-dasharray=\"6 4\"" : "") + "/>\n";
    out += "<text x=\"" + fixed(lx + 48) + "\" y=\"" + fixed(yy) + "\">" +
           escaped(curves[k].label) + "</text>\n";
  }
  out += "</svg>\n";
  return out;
}

SpeedPicture write_speed_picture(const std::filesystem::path& file, const std::string& name,
                                 double period, const std::vector<motion::Segment>& moves,
                                 const std::vector<SpeedPoint>& profile,
                                 const std::vector<motion::AxisPose>& samples,
                                 std::optional<Window> window_given) {
  SpeedCurve cncd{"cncd (servo samples)", "#d62728", 1.5, false, {0}, {0}, true};
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const double d =
        std::hypot(samples[k][0] - samples[k - 1][0], samples[k][1] - samples[k - 1][1],
                   samples[k][2] - samples[k - 1][2]);
    cncd.s.push_back(cncd.s.back() + d);
    cncd.v.push_back(d / period);
  }
  SpeedCurve reference{"time-optimal within P, Q", "#1f77b4", 2, false, {}, {}, true};
  SpeedCurve feed{"programmed feed", "#555555", 1.2, true, {}, {}, true};
  for (const auto& p : profile) {
    reference.s.push_back(p.s);
    reference.v.push_back(p.v);
    const double f = moves[p.move].feed;
    if (!feed.v.empty() && feed.v.back() != f) {
      feed.s.push_back(p.s);
      feed.v.push_back(feed.v.back());
    }
    feed.s.push_back(p.s);
    feed.v.push_back(f);
  }
  const auto window = window_given ? *window_given : slowest_window(cncd, reference, 40, 1);
  // A feed far above what the axes allow (3D_Chips') named in the legend, off the scale.
  double feed_low = 1e300, feed_high = 0, fastest = 0;
  for (std::size_t k = 0; k < feed.s.size(); ++k)
    if (feed.s[k] >= window.from && feed.s[k] <= window.to) {
      feed_low = std::min(feed_low, feed.v[k]);
      feed_high = std::max(feed_high, feed.v[k]);
    }
  for (std::size_t k = 0; k < reference.s.size(); ++k)
    if (reference.s[k] >= window.from && reference.s[k] <= window.to)
      fastest = std::max(fastest, reference.v[k]);
  if (feed_high > 2 * fastest) {
    char label[96];
    std::snprintf(label, sizeof label, "feed %g%s mm/s (off the scale)", feed_low,
                  feed_high > feed_low
                      ? (" .. " + std::to_string(static_cast<long>(feed_high))).c_str()
                      : "");
    feed.label = label;
    feed.scales = false;
  }
  char title[160];
  std::snprintf(title, sizeof title, "%s, path alone: speed along s = %g .. %g mm", name.c_str(),
                window.from, window.to);
  std::ofstream(file) << speed_svg({feed, reference, cncd}, window, title);
  const auto over = [&window](const SpeedCurve& c) {
    if (c.s.size() < 2) return 0.0;
    const auto t = times(c);
    return time_at(c, t, window.to) - time_at(c, t, window.from);
  };
  return {window, reference.s.empty() ? 0.0 : reference.s.back(), cncd.s.back(), over(cncd),
          over(reference)};
}

}  // namespace cncd::bench
