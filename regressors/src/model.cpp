#include <dicestack/core/hash.hpp>
#include <dicestack/regressors/model.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/read_file.hpp>

namespace dicestack {
namespace {

using nlohmann::json;

std::string fnv1a_hex(std::string_view bytes) {
  const std::uint64_t h = fnv1a(bytes);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

json scaler_json(const Standardizer& s) { return {{"mean", s.mean}, {"sigma", s.sigma}}; }

// Version 2: FNV-1a over the header (without this field, as dumped) and the payload, so an
// edited standardiser, parameter or dimension is caught as surely as an edited payload.
std::string whole_checksum(json header, std::string_view payload) {
  header.erase("checksum");
  return fnv1a_hex(header.dump() + '\n' + std::string(payload));
}

// An integer header field, refusing 1.5, -1 or 1e30 instead of narrowing them.
std::uint64_t header_count(const json& h, const char* key, std::uint64_t max, const std::string& where) {
  const json& v = h.at(key);
  if (!v.is_number_unsigned() || v.get<std::uint64_t>() > max)
    throw InputError(where + "header field \"" + key + "\" must be an integer in [0, " + std::to_string(max) + "], got " +
                     v.dump().substr(0, 40));
  return v.get<std::uint64_t>();
}

constexpr const char* kPickledFormat = "dicestack-pickled-regressor";

json pickled_record(std::string_view pickle, const std::string& type) {
  return {{"format", kPickledFormat}, {"version", 1}, {"object_type", type}, {"pickle_bytes", pickle.size()},
          {"pickle_fnv1a", fnv1a_hex(pickle)}};
}

// The record of a pickled payload, or nothing if the payload is not one.
std::optional<json> pickled_record_of(std::string_view payload) {
  if (payload.empty() || payload.front() != '{' || payload.size() > 4096) return std::nullopt;
  try {
    json j = parse_json_limited<json>(payload, "payload");
    if (j.is_object() && j.value("format", "") == kPickledFormat && j.contains("pickle_bytes") &&
        j["pickle_bytes"].is_number_unsigned() && j.contains("pickle_fnv1a") && j["pickle_fnv1a"].is_string())
      return j;
  } catch (const std::exception&) {  // not JSON, or too deep: not a pickled payload
  }
  return std::nullopt;
}

// The pickled record of the dicestack model file at `model`, or nothing (no such file, not a
// model, not pickled). Never throws: it decides whether a file may be replaced.
std::optional<json> pickled_record_of_file(const std::filesystem::path& model) {
  std::ifstream in(model, std::ios::binary);
  std::string first;
  if (!in || !std::getline(in, first)) return std::nullopt;
  try {
    const json h = parse_json_limited<json>(first, model.string());
    if (!h.is_object() || h.value("format", "") != kModelFormat) return std::nullopt;
    std::string payload(4097, '\0');
    in.read(payload.data(), static_cast<std::streamsize>(payload.size()));
    payload.resize(static_cast<std::size_t>(in.gcount()));
    return pickled_record_of(payload);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::optional<std::string> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), {});
}

bool matches(const std::string& bytes, const json& record) {
  return bytes.size() == record.at("pickle_bytes").get<std::uint64_t>() &&
         fnv1a_hex(bytes) == record.at("pickle_fnv1a").get<std::string>();
}

// Messages never echo long values from a file.
std::string cut(std::string text) { return text.size() > 80 ? text.substr(0, 80) + "..." : text; }

}  // namespace

std::string PickledRegressor::do_save() const { return pickled_record(pickle(), object_type()).dump(); }

std::filesystem::path pickle_path(const std::filesystem::path& model) { return model.string() + ".pkl"; }

bool is_pickled_payload(std::string_view payload) { return pickled_record_of(payload).has_value(); }

Ownership pickle_ownership(const std::filesystem::path& model) {
  return {"pickle saved with the dicestack model " + model.string(), [model](const std::filesystem::path& p) {
            const auto record = pickled_record_of_file(model);
            const auto bytes = record ? read_bytes(p) : std::nullopt;
            return bytes && matches(*bytes, *record);
          }};
}

Model::Model(std::unique_ptr<Regressor> regressor, Standardizer x, Standardizer y, const FeatureMap& features)
    : regressor_(std::move(regressor)), features_(&features), x_(std::move(x)), y_(std::move(y)) {
  if (!regressor_) throw std::logic_error("Model needs a regressor");
}

Model Model::train(std::unique_ptr<Regressor> regressor, const Matrix& x, const Matrix& y, std::uint64_t seed,
                   std::vector<std::string>* warnings, const FeatureMap& features) {
  if (x.cols() != static_cast<Eigen::Index>(features.width()) || y.cols() != static_cast<Eigen::Index>(features.outputs()))
    throw InputError("training data is " + std::to_string(x.cols()) + " -> " + std::to_string(y.cols()) +
                     " columns; a policy on features \"" + features.name() + "\" maps " +
                     std::to_string(features.width()) + " inputs to " + std::to_string(features.outputs()) + " action values");
  std::vector<std::string> names = features.column_names();
  Standardizer xs = Standardizer::fit(x, warnings, &names);
  names.clear();
  for (auto n : features.answer_names()) names.emplace_back(n);
  Standardizer ys = Standardizer::fit(y, warnings, &names);
  regressor->fit(xs.apply(x), ys.apply(y), seed);
  return Model(std::move(regressor), std::move(xs), std::move(ys), features);
}

Action Model::act(const History& history) const {
  const std::size_t width = features_->width();
  std::array<double, kMaxFeatureWidth> row, z;
  features_->compute(history, {row.data(), width});
  x_.apply_row({row.data(), width}, {z.data(), width});
  const std::size_t outputs = features_->outputs();
  std::array<double, kMaxOutputWidth> out, answer;
  regressor_->predict_row({z.data(), width}, {out.data(), outputs});
  y_.invert_row({out.data(), outputs}, {answer.data(), outputs});
  return features_->action(history, {answer.data(), outputs});
}

Action Model::act(const State& state) const { return act(History{{&state, 1}, {}}); }

Matrix Model::predict(const Matrix& rows) const {
  const Matrix z = regressor_->predict(x_.apply(rows));
  Matrix out(z.rows(), z.cols());
  for (Eigen::Index i = 0; i < z.rows(); ++i)
    y_.invert_row({z.row(i).data(), static_cast<std::size_t>(z.cols())}, {out.row(i).data(), static_cast<std::size_t>(z.cols())});
  return out;
}

Ownership model_ownership() { return Ownership::json_first_line("dicestack model file", kModelFormat); }

namespace {

// The version a model of `features` is written as: the oldest that holds it, so that older
// dicestacks keep reading every model they can run.
int model_file_version(const FeatureMap& features) {
  return features.reads_links() || features.action_kind() != ActionKind::cup ? kModelFormatVersion : 2;
}

// The model file's first line: its JSON header, which describes `payload`.
std::string model_header(const Model& model, const std::string& payload) {
  const Regressor& r = model.regressor();
  json params = json::object();
  for (const auto& [k, v] : r.params().as_text()) params[k] = v;
  json header{{"format", kModelFormat},
                    {"version", model_file_version(model.features())},
                    {"dicestack_version", DICESTACK_VERSION},
                    {"regressor", r.name()},
                    {"params", params},
                    {"features", model.features().name()},
                    {"features_version", model.features().version()},
                    {"input_dim", r.input_dim()},
                    {"input_names", model.features().column_names()},
                    {"state_dim", kStateDim},
                    {"action_dim", r.output_dim()},
                    {"state_names", state_names()},
                    {"action_names", model.features().answer_names()},
                    {"x_standardizer", scaler_json(model.x_scaler())},
                    {"y_standardizer", scaler_json(model.y_scaler())},
                    {"record", model.record},
                    {"payload_bytes", payload.size()},
                    {"payload_fnv1a", fnv1a_hex(payload)}};
  header["checksum"] = whole_checksum(header, payload);
  return header.dump();
}

}  // namespace

std::string model_to_bytes(const Model& model) {
  if (dynamic_cast<const PickledRegressor*>(&model.regressor()))
    throw InputError(model.regressor().name() + ": a Python regressor's model cannot travel between MPI ranks");
  const std::string payload = model.regressor().save_payload();
  return model_header(model, payload) + '\n' + payload;
}

void save_model(const Model& model, const std::filesystem::path& path) {
  const Regressor& r = model.regressor();
  const auto* pickled = dynamic_cast<const PickledRegressor*>(&r);
  std::string payload, pickle;
  if (pickled) {
    if (!r.fitted()) throw InputError(r.name() + ": cannot save a model that was never fitted");
    pickle = pickled->pickle();  // once: the payload describes exactly these bytes
    payload = pickled_record(pickle, pickled->object_type()).dump();
  } else {
    payload = r.save_payload();
  }
  // Both outputs are checked before either is written. The pickle is committed first, so that
  // a model file never names a pickle that is not there.
  const std::filesystem::path pkl = pickle_path(path);
  std::optional<AtomicFile> pickle_file;
  if (pickled) pickle_file.emplace(pkl, pickle_ownership(path));
  AtomicFile file(path, model_ownership());
  std::error_code ec;
  const bool stale_pickle = !pickled && std::filesystem::is_regular_file(pkl, ec) && pickle_ownership(path).recognises(pkl);
  file.stream() << model_header(model, payload) << '\n' << payload;
  if (pickle_file) {
    pickle_file->stream() << pickle;
    pickle_file->commit();
  }
  file.commit();
  if (stale_pickle) std::filesystem::remove(pkl, ec);  // the replaced model's; nothing names it now
}

Model load_model(const std::filesystem::path& path, const RegressorRegistry& registry, const PickleLoader& pickles) {
  return parse_model_file(read_file(path), path.string(), registry, pickles);
}

namespace {

// Checks the header's format and version and the payload's size and checksums; returns the version.
int check_model_header(const json& h, std::string_view payload, const std::string& where) {
  if (!h.is_object() || h.value("format", "") != kModelFormat) throw InputError(where + "format is not " + kModelFormat);
  const auto version = static_cast<int>(header_count(h, "version", 1000, where));
  if (version > kModelFormatVersion)
    throw InputError(where + "format version " + std::to_string(version) + " is newer than this dicestack reads (" +
                     std::to_string(kModelFormatVersion) + "); upgrade dicestack");
  // The payload's size against the bytes present; nothing is allocated for it.
  const auto bytes_claimed = header_count(h, "payload_bytes", std::uint64_t{1} << 40, where);
  const std::uint64_t present = payload.size();
  if (present < bytes_claimed)
    throw InputError(where + "truncated: the payload has " + std::to_string(present) + " of " +
                     std::to_string(bytes_claimed) + " bytes");
  if (present > bytes_claimed) throw InputError(where + "has bytes after the payload; corrupted");
  if (fnv1a_hex(payload) != h.at("payload_fnv1a").get<std::string>())
    throw InputError(where + "corrupted: the payload's checksum does not match the header");
  if (version >= 2 && h.at("checksum").get<std::string>() != whole_checksum(h, payload))
    throw InputError(where + "corrupted: the header's checksum does not match (the header or payload was edited)");
  return version;
}

// The model's feature map, of the version it was trained with.
const FeatureMap& model_feature_map(const json& h, int version, const std::string& where) {
  // Version 1 had no feature map: its regressors read the 24 state numbers.
  const FeatureMap& features = [&]() -> const FeatureMap& {
    try {
      return feature_map(version >= 2 ? h.at("features").get<std::string>() : "state");
    } catch (const ConfigError& e) {
      throw InputError(where + e.what() + " (upgrade dicestack?)");
    }
  }();
  if (version >= 2) {
    const auto fv = static_cast<int>(header_count(h, "features_version", 1000, where));
    if (fv != features.version())
      throw InputError(where + "feature map \"" + features.name() + "\" version " + std::to_string(fv) +
                       " differs from this dicestack's (" + std::to_string(features.version()) + "): train the model again");
  }
  return features;
}

// What a model file maps: its feature map, input width and action width.
struct ModelShape {
  const FeatureMap* features;
  std::size_t input_dim;
  std::size_t action_dim;
};

// The header's dimensions, checked against the feature map and this world's state and action sizes.
ModelShape read_model_shape(const json& h, int version, const std::string& where) {
  const auto state_dim = static_cast<std::size_t>(header_count(h, "state_dim", 1024, where));
  const auto action_dim = static_cast<std::size_t>(header_count(h, "action_dim", 1024, where));
  const FeatureMap& features = model_feature_map(h, version, where);
  const std::size_t input_dim =
      version >= 2 ? static_cast<std::size_t>(header_count(h, "input_dim", 1024, where)) : state_dim;
  if (input_dim != features.width())
    throw InputError(where + "the regressor reads " + std::to_string(input_dim) + " inputs, but feature map \"" +
                     features.name() + "\" produces " + std::to_string(features.width()));
  if (state_dim != kStateDim)
    throw InputError(where + "trained on " + std::to_string(state_dim) + "-d states, this world produces " +
                     std::to_string(kStateDim) + "-d");
  if (version < 3 && model_file_version(features) >= 3)
    throw InputError(where + "feature map \"" + features.name() + "\" (the arm's links or torques) came with format version 3; "
                     "this file says " + std::to_string(version));
  if (action_dim != features.outputs())
    throw InputError(where + "predicts " + std::to_string(action_dim) + "-d actions, feature map \"" + features.name() +
                     "\" answers " + std::to_string(features.outputs()) + "-d");
  return {&features, input_dim, action_dim};
}

// A Python regressor from the pickle beside the model file at `path`, which `record` describes.
std::unique_ptr<Regressor> load_pickled_regressor(const json& record, const std::string& name,
                                                  const std::vector<std::string>& sets, const std::string& path,
                                                  const std::string& where, const PickleLoader& pickles) {
  const std::filesystem::path pkl = pickle_path(std::filesystem::path(path));
  const std::string type = record.value("object_type", std::string("?"));
  if (!pickles)
    throw InputError(where + "regressor \"" + cut(name) + "\" is a Python object (" + cut(type) + ") pickled in " +
                     pkl.string() +
                     "; unpickling runs code, so dicestack reads it only from Python, with "
                     "dicestack.load_model(path, allow_pickle=True) (never from the command line), and only from "
                     "a source you trust");
  std::string pickle;
  try {
    pickle = read_file(pkl);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (the pickle of the model " + path + ")");
  }
  if (!matches(pickle, record))
    throw InputError(pkl.string() + ": does not match the model file " + path +
                     " (its size or FNV-1a differs from the one recorded there): they were not saved together");
  return pickles(name, sets, pickle);
}

// The header's regressor with its params, unfitted: unpickled, or made by the registry.
std::unique_ptr<Regressor> make_model_regressor(const json& h, std::string_view payload, const std::string& path,
                                                const std::string& where, const RegressorRegistry& registry,
                                                const PickleLoader& pickles) {
  const std::string name = h.at("regressor").get<std::string>();
  std::vector<std::string> sets;
  for (const auto& [k, v] : h.at("params").items()) sets.push_back(k + "=" + v.get<std::string>());
  if (const auto record = pickled_record_of(payload)) return load_pickled_regressor(*record, name, sets, path, where, pickles);
  if (!registry.contains(name))
    throw ConfigError(where + "regressor \"" + name + "\" is not registered; load its plugin with --plugin");
  try {
    return registry.create(name, sets);
  } catch (const ConfigError& e) {
    throw InputError(where + "\"params\": " + e.what());
  }
}

// The header's standardiser under `key`: `dim` means and positive sigmas.
Standardizer model_scaler(const json& h, const char* key, std::size_t dim, const std::string& where) {
  Standardizer s;
  s.mean = h.at(key).at("mean").get<std::vector<double>>();
  s.sigma = h.at(key).at("sigma").get<std::vector<double>>();
  if (s.mean.size() != dim || s.sigma.size() != dim)
    throw InputError(where + key + " has " + std::to_string(s.mean.size()) + " columns, expected " + std::to_string(dim));
  for (double v : s.sigma)
    if (!(v > 0.0) || !std::isfinite(v)) throw InputError(where + key + " has a sigma that is not positive");
  return s;
}

}  // namespace

Model parse_model_file(std::string_view bytes, const std::string& path, const RegressorRegistry& registry,
                       const PickleLoader& pickles) {
  const std::string where = path + ": ";
  const auto newline = bytes.find('\n');
  const std::string_view first = bytes.substr(0, newline);
  if (first.empty()) throw InputError(where + "empty file; not a dicestack model");
  json h;
  try {
    h = parse_json_limited<json>(first, path);
  } catch (const json::exception&) {
    throw InputError(where + "the first line is not a JSON header; not a dicestack model");
  }
  try {
    const std::string_view payload = newline == std::string_view::npos ? std::string_view() : bytes.substr(newline + 1);
    const int version = check_model_header(h, payload, where);
    const ModelShape shape = read_model_shape(h, version, where);
    std::unique_ptr<Regressor> regressor = make_model_regressor(h, payload, path, where, registry, pickles);
    Standardizer xs = model_scaler(h, "x_standardizer", shape.input_dim, where),
                 ys = model_scaler(h, "y_standardizer", shape.action_dim, where);
    try {
      regressor->load_payload(payload, shape.input_dim, shape.action_dim);
    } catch (const Error& e) {
      throw InputError(where + e.what());
    }
    Model model(std::move(regressor), std::move(xs), std::move(ys), *shape.features);
    if (h.contains("record"))
      for (const auto& [k, v] : h["record"].items()) model.record[k] = v.is_string() ? v.get<std::string>() : v.dump();
    return model;
  } catch (const json::exception& e) {
    throw InputError(where + "malformed header: " + e.what());
  }
}

}  // namespace dicestack
