// `dicestack dataset export`, `dicestack import robomimic|minari` and `dicestack bench dataset`:
// demonstrations to and from robomimic's and Minari's HDF5 layouts (docs/datasets.md).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/replay.hpp>
#include <dicestack/interop/interop.hpp>
#include <dicestack/experiments/train.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

namespace fs = std::filesystem;

struct ExportOptions {
  WorldOption world;  // for "builtin" and "human"; a folder carries its own world
  fs::path dir, out;
  std::string format, dataset_id;
  bool skip_incomplete = false;
};

struct FileImportOptions {
  WorldOption world;
  fs::path src, out;
};

std::size_t frames_of(const DemoSet& set) {
  std::size_t n = 0;
  for (const auto& e : set.episodes) n += e.size();
  return n;
}

// The set to export, with format v1's missing transitions recovered by replay where possible.
DemoSet exportable(const fs::path& spec, const WorldConfig& world, bool skip_incomplete, std::vector<std::string>& left_out) {
  const fs::path dir = resolve_demo_set(spec, world);
  DemoSet set = read_demo_set(dir);
  left_out = recover_transitions(set.episodes, set.world);
  if (left_out.empty()) return set;
  if (!skip_incomplete) {
    try {
      require_transitions(set.episodes, dir.string());
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + "; --skip-incomplete exports the others");
    }
  }
  std::erase_if(set.episodes, [](const Episode& e) { return !e.has_transitions(); });
  if (set.episodes.empty()) throw InputError(dir.string() + ": no episode has a final state; nothing to export");
  return set;
}

void export_set(const DemoSet& set, const std::string& format, const fs::path& out, const std::string& dataset_id) {
  if (format == "robomimic") export_robomimic(set, out);
  else export_minari(set, out, dataset_id);
}

int run_export(const ExportOptions& opt) {
  std::vector<std::string> left_out;
  const DemoSet set = exportable(opt.dir, opt.world.load(), opt.skip_incomplete, left_out);
  // The name the user gave ("builtin", "human" or a folder), not the cache folder it stands for.
  const std::string id = opt.dataset_id.empty() ? default_minari_dataset_id(opt.dir) : opt.dataset_id;
  export_set(set, opt.format, opt.out, id);
  if (!left_out.empty()) {
    std::string names;
    for (std::size_t i = 0; i < left_out.size() && i < 10; ++i) names += (i ? ", " : "") + left_out[i];
    if (left_out.size() > 10) names += " and " + std::to_string(left_out.size() - 10) + " more";
    print_line("left out " + std::to_string(left_out.size()) + " episodes without a final state (they do not replay): " + names);
  }
  print_line("exported " + std::to_string(set.episodes.size()) + " episodes (" + std::to_string(frames_of(set)) +
             " frames) as " + opt.format + (opt.format == "minari" ? " dataset " + id : std::string()) + " to " +
             opt.out.string());
  return 0;
}

int run_import_file(const FileImportOptions& opt, const std::string& format) {
  check_demo_set_replaceable(opt.out);  // before any work
  DemoSet set = format == "robomimic" ? import_robomimic(opt.src) : import_minari(opt.src, opt.world.load());
  set.provenance = "dicestack import " + format + " " + opt.src.string() + (set.provenance.empty() ? "" : "; " + set.provenance);
  write_demo_set(set, opt.out);
  print_line("imported " + std::to_string(set.episodes.size()) + " episodes (" + std::to_string(frames_of(set)) +
             " frames) from " + opt.src.string() + " into " + opt.out.string());
  return 0;
}

struct InteropBenchOptions {
  WorldOption world;
  std::vector<std::string> demos{"builtin", "human"};
  int repeats = 3;
  bool json = false;
};

// Export and import throughput (frames/s) of each set in both layouts: medians of `repeats` runs.
// "export" and "import" include reading or writing our folder (what the commands cost); the
// "hdf5" figures time the HDF5 side alone (a set in memory to the file, the file to a set).
int run_bench_dataset(const InteropBenchOptions& opt) {
  const WorldConfig world = opt.world.load();
  const fs::path scratch = fs::temp_directory_path() / ("dicestack-bench-dataset-" + std::to_string(getpid()));
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& spec : opt.demos) {
    std::vector<std::string> left_out;
    const DemoSet set = exportable(spec, world, false, left_out);
    const fs::path dir = resolve_demo_set(spec, world);
    const double frames = static_cast<double>(frames_of(set));
    for (const std::string format : {"robomimic", "minari"}) {
      const fs::path file = scratch / (format == std::string("robomimic") ? "set.hdf5" : "minari");
      const fs::path back = scratch / "back";
      std::vector<double> out_s, in_s, h5_out_s, h5_in_s;
      for (int r = 0; r < opt.repeats; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        DemoSet read = read_demo_set(dir);
        recover_transitions(read.episodes, read.world);
        const auto t1 = std::chrono::steady_clock::now();
        export_set(read, format, file, "dicestack/bench-v0");
        h5_out_s.push_back(seconds_since(t1));
        out_s.push_back(seconds_since(t0));
        t0 = std::chrono::steady_clock::now();
        const DemoSet in = format == std::string("robomimic") ? import_robomimic(file) : import_minari(file, world);
        h5_in_s.push_back(seconds_since(t0));
        write_demo_set(in, back);
        in_s.push_back(seconds_since(t0));
      }
      auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
      };
      const double out_m = median(out_s), in_m = median(in_s), h5_out_m = median(h5_out_s), h5_in_m = median(h5_in_s);
      std::uintmax_t bytes = 0;
      if (fs::is_directory(file)) {
        for (const auto& f : fs::recursive_directory_iterator(file))
          if (f.is_regular_file()) bytes += f.file_size();
      } else {
        bytes = fs::file_size(file);
      }
      rows.push_back({{"demos", spec}, {"format", format}, {"episodes", set.episodes.size()}, {"frames", frames_of(set)},
                      {"bytes", bytes}, {"export_s", out_m}, {"import_s", in_m}, {"export_frames_per_s", frames / out_m},
                      {"import_frames_per_s", frames / in_m}, {"hdf5_export_s", h5_out_m}, {"hdf5_import_s", h5_in_m},
                      {"hdf5_export_frames_per_s", frames / h5_out_m}, {"hdf5_import_frames_per_s", frames / h5_in_m},
                      {"repeats", opt.repeats}});
      if (!opt.json) {
        char line[320];
        std::snprintf(line, sizeof line,
                      "bench dataset: %-8s %-9s %3zu episodes %6.0f frames %6.2f MB: export %.3f s (%.0f frames/s; HDF5 "
                      "side %.0f frames/s), import %.3f s (%.0f frames/s; HDF5 side %.0f frames/s); medians of %d",
                      spec.c_str(), format.c_str(), set.episodes.size(), frames, static_cast<double>(bytes) / 1e6, out_m,
                      frames / out_m, frames / h5_out_m, in_m, frames / in_m, frames / h5_in_m, opt.repeats);
        print_line(line);
      }
    }
  }
  fs::remove_all(scratch);
  if (opt.json) print_line(rows.dump());
  return 0;
}

}  // namespace

void add_interop_commands(CLI::App& import, CLI::App& dataset) {
  auto imp = std::make_shared<FileImportOptions>();
  CLI::App* cmd = import.add_subcommand("robomimic", "A robomimic HDF5 file of dicestack's environment (as `dataset export --format robomimic` writes)");
  cmd->add_option("file", imp->src, "FILE.hdf5")->required();
  cmd->add_option("--out", imp->out, "Folder to write the demonstration set to (missing, empty, or a dicestack set, which is replaced whole)")->required();
  cmd->callback([imp] { run_import_file(*imp, "robomimic"); });

  auto mimp = std::make_shared<FileImportOptions>();
  cmd = import.add_subcommand("minari", "A Minari dataset folder (DIR/data/main_data.hdf5 and metadata.json)");
  cmd->add_option("dir", mimp->src, "Minari dataset folder")->required();
  cmd->add_option("--out", mimp->out, "Folder to write the demonstration set to (missing, empty, or a dicestack set, which is replaced whole)")->required();
  mimp->world.add_to(*cmd);
  cmd->callback([mimp] { run_import_file(*mimp, "minari"); });

  auto exp = std::make_shared<ExportOptions>();
  cmd = dataset.add_subcommand("export", "Write a set in robomimic's or Minari's HDF5 layout");
  cmd->add_option("dir", exp->dir, "Demonstration folder, or builtin, or human")->required();
  cmd->add_option("--format", exp->format, "robomimic (one FILE.hdf5) or minari (a dataset folder)")
      ->required()
      ->check(CLI::IsMember({"robomimic", "minari"}));
  cmd->add_option("--out", exp->out, "robomimic: FILE.hdf5; minari: a folder (missing, empty, or one of our exports, replaced whole)")->required();
  cmd->add_option("--dataset-id", exp->dataset_id, "minari: the dataset id (default dicestack/<folder name>-v0)");
  cmd->add_flag("--skip-incomplete", exp->skip_incomplete,
                "Leave out (and name) episodes of a format-v1 set whose final state cannot be recovered by replay");
  exp->world.add_to(*cmd);
  cmd->callback([exp] { run_export(*exp); });
}

void add_bench_dataset_command(CLI::App& bench) {
  auto opt = std::make_shared<InteropBenchOptions>();
  CLI::App* cmd = bench.add_subcommand("dataset", "Export and import throughput (frames/s) of the robomimic and Minari layouts");
  opt->world.add_to(*cmd);
  cmd->add_option("--demos", opt->demos, "Sets to measure (folders, builtin, human)")->capture_default_str();
  cmd->add_option("--repeats", opt->repeats, "Runs (the median is reported)")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON array");
  cmd->callback([opt] { run_bench_dataset(*opt); });
}

}  // namespace dicestack::cli
