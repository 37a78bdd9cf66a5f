#include <dicestack/experiments/learning_curve.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/policy.hpp>
#include <dicestack/experiments/train.hpp>
#include <dicestack/version.hpp>

namespace dicestack {
namespace {

using json = nlohmann::json;

constexpr std::uint64_t kCurveDrawStream = 0x647261770000ULL;  // "draw": apart from training and evaluation starts
constexpr const char* kCurveMarker = "<!-- dicestack learning curve -->";
constexpr const char* kCurveCsvHeader =
    "learner,regressor,recordings,draw_seed,episodes,realistic_success,realistic_success_low,realistic_success_high,"
    "wall_contact,dice_in_cup_mean,train_seconds,recordings_drawn,followed";
constexpr const char* kCurveJsonFormat = "dicestack-learning-curve";

std::string percent(double v) {
  char out[16];
  std::snprintf(out, sizeof out, "%.0f%%", 100.0 * v);
  return out;
}

// The learner options of `spec` and every --option whose key its schema has.
std::vector<std::string> options_for(const LearnerSpec& spec, const std::vector<std::string>& options) {
  std::vector<std::string> out = spec.options;
  const LearnerInfo& info = LearnerRegistry::global().info(spec.name);
  for (const auto& o : options) {
    const std::string key = o.substr(0, o.find('='));
    if (std::any_of(info.params.begin(), info.params.end(), [&](const ParamSpec& p) { return p.name == key; })) out.push_back(o);
  }
  return out;
}

// A learner's mean, lowest and highest success over the draws of one number.
struct Summary {
  std::string learner, regressor;
  int recordings = 0, draws = 0;
  double mean = 0.0, low = 1.0, high = 0.0, walls = 0.0;
};

std::vector<Summary> summarise(const LearningCurve& curve) {
  std::vector<Summary> out;
  for (const auto& p : curve.points) {
    auto it = std::find_if(out.begin(), out.end(), [&](const Summary& s) {
      return s.learner == p.learner && s.regressor == p.regressor && s.recordings == p.recordings;
    });
    if (it == out.end()) {
      Summary fresh;
      fresh.learner = p.learner;
      fresh.regressor = p.regressor;
      fresh.recordings = p.recordings;
      it = out.insert(out.end(), fresh);
    }
    it->draws += 1;
    it->mean += p.success.value;
    it->walls += p.walls.value;
    it->low = std::min(it->low, p.success.value);
    it->high = std::max(it->high, p.success.value);
  }
  for (auto& s : out) s.mean /= s.draws, s.walls /= s.draws;
  return out;
}

std::string draw_names(const LearningCurvePoint& p) {
  std::string out;
  for (const auto& n : p.names) out += (out.empty() ? "" : " ") + n;
  return out;
}

std::string render_md(const LearningCurve& c) {
  std::ostringstream os;
  os << kCurveMarker << "\n" << c.header << "\n\n";
  os << "| learner | regressor | recordings | draws | realistic success (mean) | lowest | highest | wall contact (mean) |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& s : summarise(c))
    os << "| " << s.learner << " | " << s.regressor << " | " << s.recordings << " | " << s.draws << " | " << percent(s.mean)
       << " | " << percent(s.low) << " | " << percent(s.high) << " | " << percent(s.walls) << " |\n";
  os << "\nEvery draw:\n\n| learner | regressor | recordings | draw seed | realistic success [95% CI] | wall contact | "
        "dice in cup | train s | followed |\n|---|---|---:|---:|---:|---:|---:|---:|---|\n";
  // Streamed, not formatted into a buffer: the followed paths of a tracker that keeps several are long.
  for (const auto& p : c.points) {
    char numbers[64];
    std::snprintf(numbers, sizeof numbers, "%.2f | %.0f", p.dice_in_cup, p.train_seconds);
    os << "| " << p.learner << " | " << p.regressor << " | " << p.recordings << " | " << p.draw_seed << " | "
       << percent(p.success.value) << " [" << percent(p.success.low) << "-" << percent(p.success.high) << "] | "
       << percent(p.walls.value) << " | " << numbers << " | " << (p.followed.empty() ? "-" : p.followed) << " |\n";
  }
  return os.str();
}

std::string csv_field(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string render_csv(const LearningCurve& c) {
  std::ostringstream os;
  os.precision(6);
  os << kCurveCsvHeader << "\n";
  for (const auto& p : c.points)
    os << p.learner << ',' << p.regressor << ',' << p.recordings << ',' << p.draw_seed << ',' << p.episodes << ','
       << p.success.value << ',' << p.success.low << ',' << p.success.high << ',' << p.walls.value << ',' << p.dice_in_cup
       << ',' << p.train_seconds << ',' << csv_field(draw_names(p)) << ',' << csv_field(p.followed) << "\n";
  return os.str();
}

json to_json(const LearningCurve& c) {
  json points = json::array();
  for (const auto& p : c.points)
    points.push_back({{"learner", p.learner}, {"regressor", p.regressor}, {"recordings", p.recordings},
                      {"draw_seed", p.draw_seed}, {"recordings_drawn", p.names}, {"episodes", p.episodes},
                      {"realistic_success", p.success.value}, {"realistic_success_ci95", {p.success.value, p.success.low, p.success.high}},
                      {"wall_contact", p.walls.value}, {"dice_in_cup_mean", p.dice_in_cup},
                      {"train_seconds", p.train_seconds}, {"followed", p.followed}});
  return {{"format", kCurveJsonFormat}, {"version", 1}, {"dicestack_version", DICESTACK_VERSION}, {"header", c.header}, {"points", points}};
}

std::string escape_html(const std::string& s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += ch;
    }
  }
  return out;
}

// Success against recordings (a log scale), a line through each learner's means and a dot per draw.
std::string svg_plot(const LearningCurve& c) {
  const double w = 640, h = 360, left = 56, right = 160, top = 16, bottom = 44;
  int most = 1;
  for (const auto& p : c.points) most = std::max(most, p.recordings);
  const double span = std::log(static_cast<double>(std::max(most, 2)));
  auto x = [&](int k) { return left + (w - left - right) * std::log(static_cast<double>(k)) / span; };
  auto y = [&](double v) { return top + (h - top - bottom) * (1.0 - v); };
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};
  std::ostringstream os;
  os.precision(4);
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " << w << ' ' << h << "\" width=\"" << w << "\" height=\"" << h
     << "\" role=\"img\" aria-label=\"realistic success against recordings\">\n";
  for (int v = 0; v <= 100; v += 25)
    os << "<line x1=\"" << left << "\" x2=\"" << w - right << "\" y1=\"" << y(v / 100.0) << "\" y2=\"" << y(v / 100.0)
       << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << y(v / 100.0) + 4 << "\" text-anchor=\"end\" font-size=\"11\">"
       << v << "%</text>\n";
  std::set<int> ticks;
  for (const auto& p : c.points) ticks.insert(p.recordings);
  for (int k : ticks)
    os << "<text x=\"" << x(k) << "\" y=\"" << h - bottom + 16 << "\" text-anchor=\"middle\" font-size=\"11\">" << k << "</text>\n";
  os << "<text x=\"" << (left + w - right) / 2 << "\" y=\"" << h - 8 << "\" text-anchor=\"middle\" font-size=\"12\">recordings</text>\n";
  std::vector<std::string> series;
  for (const auto& s : summarise(c)) {
    const std::string name = s.learner + " " + s.regressor;
    if (std::find(series.begin(), series.end(), name) == series.end()) series.push_back(name);
  }
  for (std::size_t i = 0; i < series.size(); ++i) {
    const char* colour = colours[i % 6];
    std::string line;
    for (const auto& s : summarise(c))
      if (s.learner + " " + s.regressor == series[i])
        line += (line.empty() ? "" : " ") + std::to_string(x(s.recordings)) + "," + std::to_string(y(s.mean));
    os << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\" points=\"" << line << "\"/>\n";
    for (const auto& p : c.points)
      if (p.learner + " " + p.regressor == series[i])
        os << "<circle cx=\"" << x(p.recordings) << "\" cy=\"" << y(p.success.value) << "\" r=\"3\" fill=\"" << colour
           << "\" opacity=\"0.6\"><title>" << escape_html(p.learner) << ", " << p.recordings << " recordings, draw "
           << p.draw_seed << ": " << percent(p.success.value) << "</title></circle>\n";
    os << "<text x=\"" << w - right + 10 << "\" y=\"" << top + 14 + 18 * static_cast<double>(i) << "\" font-size=\"12\" fill=\""
       << colour << "\">" << escape_html(series[i]) << "</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

std::string render_html(const LearningCurve& c) {
  std::ostringstream os;
  os << "<!DOCTYPE html>" << kCurveMarker << "\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>dicestack learning curve</title>\n"
     << "<style>body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;max-width:60em}table{border-collapse:collapse;margin:1em 0}"
        "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}td:first-child,th:first-child{text-align:left}"
        "svg{max-width:100%;height:auto}</style></head><body>\n<h1>Realistic success against recordings</h1>\n<p>"
     << escape_html(c.header) << "</p>\n" << svg_plot(c)
     << "<table><tr><th>learner</th><th>regressor</th><th>recordings</th><th>draws</th><th>mean</th><th>lowest</th>"
        "<th>highest</th><th>wall contact</th></tr>\n";
  for (const auto& s : summarise(c))
    os << "<tr><td>" << escape_html(s.learner) << "</td><td>" << escape_html(s.regressor) << "</td><td>" << s.recordings
       << "</td><td>" << s.draws << "</td><td>" << percent(s.mean) << "</td><td>" << percent(s.low) << "</td><td>"
       << percent(s.high) << "</td><td>" << percent(s.walls) << "</td></tr>\n";
  os << "</table>\n<table><tr><th>learner</th><th>recordings</th><th>draw seed</th><th>success</th><th>walls</th>"
        "<th>recordings drawn</th><th>followed</th></tr>\n";
  for (const auto& p : c.points)
    os << "<tr><td>" << escape_html(p.learner + " " + p.regressor) << "</td><td>" << p.recordings << "</td><td>" << p.draw_seed
       << "</td><td>" << percent(p.success.value) << "</td><td>" << percent(p.walls.value) << "</td><td>"
       << escape_html(draw_names(p)) << "</td><td>" << escape_html(p.followed) << "</td></tr>\n";
  os << "</table>\n</body></html>\n";
  return os.str();
}

// The first line of each format: the marker (md, html), the header (csv), the JSON object.
Ownership curve_ownership() {
  const Ownership lines = Ownership::first_line(
      "dicestack learning curve", {kCurveMarker, std::string("<!DOCTYPE html>") + kCurveMarker, kCurveCsvHeader});
  const Ownership object = Ownership::json_first_line("dicestack learning curve", kCurveJsonFormat);
  return {"dicestack learning curve",
          [lines, object](const std::filesystem::path& p) { return lines.recognises(p) || object.recognises(p); }};
}

}  // namespace

std::vector<Episode> draw_recordings(const std::vector<Episode>& episodes, int k, std::uint64_t seed) {
  if (k < 1) throw ConfigError("recordings: a draw needs at least 1 recording, got " + std::to_string(k));
  if (static_cast<std::size_t>(k) >= episodes.size()) return episodes;
  std::vector<std::size_t> index(episodes.size());
  for (std::size_t i = 0; i < index.size(); ++i) index[i] = i;
  Rng rng(derive_seed(seed, kCurveDrawStream));
  for (std::size_t i = 0; i < static_cast<std::size_t>(k); ++i) std::swap(index[i], index[i + rng.below(index.size() - i)]);
  index.resize(static_cast<std::size_t>(k));
  std::sort(index.begin(), index.end());
  std::vector<Episode> out;
  for (std::size_t i : index) out.push_back(episodes[i]);
  return out;
}

LearningCurve run_learning_curve(const LearningCurveRequest& r, const LearningCurveProgress& progress) {
  // Everything a run would refuse, before any work.
  if (r.recordings.empty()) throw ConfigError("recordings: give at least one number");
  for (int k : r.recordings)
    if (k < 1 || k > 1000000) throw ConfigError("recordings: each number must be in [1, 1000000], got " + std::to_string(k));
  if (r.draws < 1 || r.draws > 1000) throw ConfigError("draws must be in [1, 1000], got " + std::to_string(r.draws));
  const std::vector<std::string> learner_texts =
      r.learners.empty() ? std::vector<std::string>{"dart:expert=tracker", "dad"} : r.learners;
  std::vector<LearnerSpec> specs;
  for (const auto& t : learner_texts) specs.push_back(parse_learner_spec(t));
  const std::vector<std::string> regressors = r.regressors.empty() ? std::vector<std::string>{"gbt"} : r.regressors;
  for (const auto& reg : regressors) RegressorRegistry::global().create(reg, {});
  for (const auto& spec : specs) LearnerRegistry::global().create(spec.name, options_for(spec, r.options));
  EvalRequest eval;
  eval.episodes = r.episodes;
  eval.seed = r.seed;
  eval.threads = r.threads;
  check_evaluation(r.world, eval);

  const auto folder = resolve_demo_set(r.demos, r.world);
  const std::vector<Episode> all = read_demo_set(folder).episodes;
  std::set<int> counts(r.recordings.begin(), r.recordings.end());
  LearningCurve curve;
  {
    std::ostringstream h;
    h << "dicestack " DICESTACK_VERSION " learning curve: recordings drawn from " << folder.string() << " (" << all.size()
      << " episodes), " << r.draws << " draw(s) of each number (seeds " << r.seed << "..." << r.seed + r.draws - 1
      << "); each policy trained with seed " << r.seed << " on its draw alone and rolled out from " << r.episodes
      << " random starts (seed " << r.seed << ")";
    curve.header = h.str();
  }
  for (const int k : counts) {
    const int draws = static_cast<std::size_t>(k) >= all.size() ? 1 : r.draws;
    for (int d = 0; d < draws; ++d) {
      const std::uint64_t draw_seed = r.seed + static_cast<std::uint64_t>(d);
      const std::vector<Episode> drawn = draw_recordings(all, k, draw_seed);
      for (const auto& spec : specs)
        for (const auto& reg : regressors) {
          LearningCurvePoint p;
          p.learner = spec.text;
          p.regressor = reg;
          p.recordings = static_cast<int>(drawn.size());
          p.draw_seed = draw_seed;
          for (const auto& e : drawn) p.names.push_back(e.name);
          if (progress) progress(spec.text + " " + reg + ": " + std::to_string(drawn.size()) + " recordings, draw " + std::to_string(draw_seed) + ": training");
          TrainRequest t;
          t.world = r.world;
          t.demos = drawn;
          t.demos_name = folder.string() + " (" + std::to_string(drawn.size()) + " drawn with seed " + std::to_string(draw_seed) + ")";
          t.regressor = reg;
          t.learner = spec.name;
          t.learner_options = options_for(spec, r.options);
          t.split = "none";
          t.seed = r.seed;
          t.threads = r.threads;
          t.cluster = r.cluster;
          const TrainReport trained = train_model(t);
          p.train_seconds = trained.seconds;
          const auto& record = trained.result.model->record;
          if (record.contains("tracker_followed")) p.followed = record.at("tracker_followed");
          std::shared_ptr<const Model> model = trained.result.model;
          const EvalStats s = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, r.world, eval, *r.cluster);
          p.episodes = s.episodes;
          p.success = s.realistic_success;
          p.walls = s.wall_contact;
          p.dice_in_cup = s.dice_in_cup_mean;
          if (progress) progress(spec.text + " " + reg + ": " + std::to_string(drawn.size()) + " recordings, draw " + std::to_string(draw_seed) + ": " + percent(p.success.value) + " realistic success");
          curve.points.push_back(std::move(p));
        }
    }
  }
  return curve;
}

std::vector<std::string> learning_curve_formats() { return {"md", "csv", "json", "html"}; }

std::string render_learning_curve(const LearningCurve& curve, const std::string& format) {
  if (format == "md") return render_md(curve);
  if (format == "csv") return render_csv(curve);
  if (format == "json") return to_json(curve).dump() + "\n";  // one line: its first line names its format
  if (format == "html") return render_html(curve);
  throw ConfigError("learning curve: unknown format \"" + format + "\"; expected md, csv, json or html");
}

void check_learning_curve_replaceable(const std::filesystem::path& out) { check_replaceable(out, curve_ownership()); }

void write_learning_curve(const LearningCurve& curve, const std::string& format, const std::filesystem::path& out) {
  const std::string text = render_learning_curve(curve, format);
  AtomicFile f(out, curve_ownership());
  f.stream() << text;
  f.commit();
}

}  // namespace dicestack
