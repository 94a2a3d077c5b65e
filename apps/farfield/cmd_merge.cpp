// farfield merge SHARD.imp... -o city.imp       joins the shards of `farfield bake --shard K/N` into one database
// farfield merge --compare A.imp B.imp          says whether two databases hold the same records (exit 1 if not)
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "farfield/bake/merge.h"
#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/store_compare.h"

namespace farfield::app {
namespace {

struct MergeArgs {
  std::vector<std::string> inputs;
  std::string out_dir;
  bool compare = false;
};

int compareStores(const MergeArgs& args) {
  if (args.inputs.size() != 2 || !args.out_dir.empty())
    throw Error("--compare", "takes exactly two databases and no -o");
  const nlohmann::json a = store::comparableRecords(store::readIndex(args.inputs[0]), false);
  const nlohmann::json b = store::comparableRecords(store::readIndex(args.inputs[1]), false);
  const std::string difference = store::firstDifference(a, b);
  if (!difference.empty()) {
    std::printf("different records: %s\n", difference.c_str());
    return 1;
  }
  std::printf("same records: %zu cells (timings and generation numbers aside)\n", a["cells"].size());
  return 0;
}

const RegisterCommand reg("merge", [](CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  auto* cmd = app.add_subcommand("merge", "Join the shard databases of farfield bake --shard K/N into one database, "
                                          "checking that every view region is present once; or --compare two "
                                          "databases record by record.");
  cmd->add_option("inputs", args->inputs, "Shard databases (all N of them), or the two databases to compare")
      ->required();
  cmd->add_option("-o,--output", args->out_dir, "The merged database directory");
  cmd->add_flag("--compare", args->compare, "Compare two databases (timings and generation numbers aside): exit 0 "
                                            "when their records are the same, 1 when not");
  cmd->callback([args] {
    if (args->compare) {
      const int status = compareStores(*args);
      std::fflush(stdout);
      if (status != 0) std::exit(status);  // a comparison's answer, not an error
      return;
    }
    if (args->out_dir.empty()) throw Error("-o", "an output directory is needed");
    const bake::MergeReport r = bake::mergeShards(args->inputs, args->out_dir);
    std::printf("merged %zu shards: %zu cells, %zu files (%zu hard-linked, %zu copied), %.1f MB, %.2f s\n", r.shards,
                r.cells, r.files, r.linked, r.files - r.linked, double(r.bytes) / 1e6, r.wall_s);
    std::printf("wrote %s/index.json\n", args->out_dir.c_str());
  });
});

}  // namespace
}  // namespace farfield::app
