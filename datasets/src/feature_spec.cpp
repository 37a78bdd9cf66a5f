// A feature map's name, read and written part by part (FeatureSpec's grammar in features.hpp).
#include <algorithm>
#include <array>
#include <string>
#include <string_view>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/features.hpp>

namespace dicestack {
namespace {

constexpr std::string_view kDiceFrame = "@dice";
constexpr std::string_view kGrammarHint =
    "a map is parts joined by \"+\", each once and in this order: state or cup, links, clock, start or start_state "
    "(either may end in @dice), history, retry; then /velocity, /position, /torque or /osc; then /ahead or /landing";

// An input part's place in a name: parts of one rank exclude each other.
enum Rank { kCurrentRank, kLinksRank, kClockRank, kStartRank, kHistoryRank, kRetryRank };

struct PartName {
  std::string_view text;
  Rank rank;
};
constexpr std::array<PartName, 8> kParts{{{"state", kCurrentRank},
                                          {"cup", kCurrentRank},
                                          {"links", kLinksRank},
                                          {"clock", kClockRank},
                                          {"start", kStartRank},
                                          {"start_state", kStartRank},
                                          {"history", kHistoryRank},
                                          {"retry", kRetryRank}}};

[[noreturn]] void bad_feature_name(std::string_view name, const std::string& what) {
  throw ConfigError("feature map \"" + std::string(name) + "\": " + what + "; " + std::string(kGrammarHint));
}

std::string in_quotes(std::string_view s) { return "\"" + std::string(s) + "\""; }

// Sets the one input `part` (its "@dice" already taken off) names.
void set_part(FeatureSpec& spec, std::string_view part) {
  using C = FeatureSpec::Current;
  using S = FeatureSpec::Start;
  if (part == "state") spec.current = C::state;
  if (part == "cup") spec.current = C::cup;
  if (part == "links") spec.links = true;
  if (part == "clock") spec.clock = true;
  if (part == "start") spec.start = S::summary;
  if (part == "start_state") spec.start = S::whole;
  if (part == "history") spec.previous = true;
  if (part == "retry") spec.restart = true;
}

void parse_inputs(std::string_view name, std::string_view inputs, FeatureSpec& spec) {
  std::string_view last;  // the previous part, for an out-of-order message
  int last_rank = -1;
  for (std::size_t at = 0;;) {
    const std::size_t plus = inputs.find('+', at);
    std::string_view part = inputs.substr(at, plus == std::string_view::npos ? plus : plus - at);
    const std::string_view given = part;
    if (part.empty()) bad_feature_name(name, "an empty part");
    const bool dice = part.ends_with(kDiceFrame);
    if (dice) part.remove_suffix(kDiceFrame.size());
    const auto* known = std::find_if(kParts.begin(), kParts.end(), [&](const PartName& p) { return p.text == part; });
    if (known == kParts.end()) bad_feature_name(name, "unknown part " + in_quotes(given));
    if (dice && known->rank != kStartRank) bad_feature_name(name, in_quotes(kDiceFrame) + " follows start or start_state, not " + in_quotes(part));
    if (given == last) bad_feature_name(name, in_quotes(given) + " given twice");
    if (known->rank == last_rank) bad_feature_name(name, in_quotes(given) + " after " + in_quotes(last) + ": give one of them");
    if (known->rank < last_rank) bad_feature_name(name, in_quotes(given) + " must come before " + in_quotes(last));
    set_part(spec, part);
    spec.dice_frame = spec.dice_frame || dice;
    last = given;
    last_rank = known->rank;
    if (plus == std::string_view::npos) break;
    at = plus + 1;
  }
  if (spec.restart && !spec.clock && spec.start == FeatureSpec::Start::none)
    bad_feature_name(name, "\"retry\" restarts the clock and the start: give clock or a start before it");
}

void parse_suffix(std::string_view name, std::string_view suffix, int& last_rank, FeatureSpec& spec) {
  using T = FeatureSpec::Timing;
  const std::string slash = "/" + std::string(suffix);
  int rank = -1;
  if (suffix == "velocity" || suffix == "position" || suffix == "torque" || suffix == "osc") {
    rank = 0;
    spec.target = suffix == "velocity"   ? ActionTarget::velocity
                  : suffix == "position" ? ActionTarget::position
                  : suffix == "torque"   ? ActionTarget::torque
                                         : ActionTarget::osc;
  } else if (suffix == "ahead" || suffix == "landing") {
    rank = 1;
    spec.timing = suffix == "ahead" ? T::ahead : T::landing;
  } else {
    bad_feature_name(name, "unknown suffix " + in_quotes(slash));
  }
  if (rank == last_rank) bad_feature_name(name, in_quotes(slash) + " given with another " + (rank == 0 ? "target" : "timing"));
  if (rank < last_rank) bad_feature_name(name, in_quotes(slash) + " must come before the timing");
  // A delay's pending and unseen actions move the cup ahead as cup actions; torques do not.
  if (rank == 1 && (spec.target == ActionTarget::torque || spec.target == ActionTarget::osc))
    bad_feature_name(name, in_quotes(slash) + " moves the cup ahead by cup actions; a map in joint torques takes no timing");
  last_rank = rank;
}

}  // namespace

FeatureSpec parse_feature_spec(std::string_view name) {
  FeatureSpec spec;
  const std::size_t slash = name.find('/');
  parse_inputs(name, name.substr(0, slash), spec);
  int last_rank = -1;
  for (std::size_t at = slash; at != std::string_view::npos;) {
    const std::size_t next = name.find('/', at + 1);
    parse_suffix(name, name.substr(at + 1, next == std::string_view::npos ? next : next - at - 1), last_rank, spec);
    at = next;
  }
  if (spec.target == ActionTarget::osc && !spec.links)
    bad_feature_name(name, "\"/osc\" servos the cup through the arm's links: give links among its parts");
  return spec;
}

std::string torque_map_name(std::string_view name) {
  FeatureSpec spec = parse_feature_spec(name);
  spec.links = true;
  spec.target = ActionTarget::osc;
  spec.timing = FeatureSpec::Timing::now;
  return to_string(spec);
}

std::string to_string(const FeatureSpec& spec) {
  using C = FeatureSpec::Current;
  using S = FeatureSpec::Start;
  using T = FeatureSpec::Timing;
  std::string out;
  const auto add = [&out](std::string_view part) { out += (out.empty() ? "" : "+") + std::string(part); };
  if (spec.current != C::none) add(spec.current == C::state ? "state" : "cup");
  if (spec.links) add("links");
  if (spec.clock) add("clock");
  if (spec.start != S::none) add(std::string(spec.start == S::whole ? "start_state" : "start") + (spec.dice_frame ? "@dice" : ""));
  if (spec.previous) add("history");
  if (spec.restart) add("retry");
  if (spec.target == ActionTarget::velocity) out += kVelocityTargetSuffix;
  if (spec.target == ActionTarget::position) out += kPositionTargetSuffix;
  if (spec.target == ActionTarget::torque) out += kTorqueTargetSuffix;
  if (spec.target == ActionTarget::osc) out += kOscTargetSuffix;
  if (spec.timing == T::ahead) out += kAheadSuffix;
  if (spec.timing == T::landing) out += kLandingSuffix;
  return out;
}

}  // namespace dicestack
