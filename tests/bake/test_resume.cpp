// Resuming a killed bake (bake/pipeline.h, store/bake_journal.h): a crash at a file operation of a bake (simulated
// by the store's file-operation hook throwing there) followed by --resume gives the records of an uninterrupted
// bake, keeps every cell the journal finished, and the previous database in the directory stays readable at every
// file operation until the new index replaces it. (The CLI test cli.bake_resume kills real processes with kill -9.)
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "farfield/bake/pipeline.h"
#include "farfield/core/error.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/store/bake_journal.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/store_compare.h"
#include "farfield/urban/cells.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::bake {
namespace {

struct Crash {};  // what the hook throws: the bake stops there as a killed one would

struct ResumeCity {
  gen::City city;
  std::unique_ptr<urban::CellMap> cells;
  std::vector<uint32_t> view_space, earlier;
  extract::PipelineOptions options;
};

const ResumeCity& resumeCity() {
  static const ResumeCity* c = [] {
    auto* s = new ResumeCity;
    gen::CityOptions o;
    o.blocks = 10;
    o.detail = 0;
    o.seed = 17;
    o.objects = gen::ObjectGrouping::Buildings;
    s->city = gen::generateCity(o);
    s->cells = std::make_unique<urban::CellMap>(s->city.streets, s->city.scene);
    for (uint32_t e = 1; e < s->cells->cellCount() && s->view_space.size() < 4; e += 4)
      if (!s->cells->degenerate(e)) s->view_space.push_back(e);
    s->earlier = {s->view_space[0]};
    s->options.base.resolution = 64;
    s->options.base.progress = false;
    s->options.base.workers = 2;
    s->options.pvs.spacing = 12.0f;
    s->options.pvs.face_size = 48;
    s->options.frame_width = 256;
    s->options.frame_height = 256;
    s->options.grid_cells = 12;
    s->options.station_spacing = 20.0f;
    return s;
  }();
  return *c;
}

PipelineReport bake(const std::string& dir, const std::vector<uint32_t>& cells, bool resume) {
  const ResumeCity& c = resumeCity();
  return bakePipeline(gpu::sharedHeadlessContext(), c.city.scene, *c.cells, cells,
                      extract::parsePipeline("pvs,near-far,single,mmi"), c.options, dir, BakeControl{{}, resume});
}

TEST(BakeResumeTest, ACrashAtAnyStageThenResumeGivesTheUninterruptedRecordsAndTheOldDatabaseStaysReadable) {
  const std::string reference = test::scratchDir("resume_reference").string();
  bake(reference, resumeCity().view_space, false);
  const nlohmann::json expected = store::comparableRecords(store::readIndex(reference));

  // How many file operations an uninterrupted bake makes (into a directory holding an earlier database).
  size_t operations = 0;
  {
    const std::string dir = test::scratchDir("resume_count").string();
    bake(dir, resumeCity().earlier, false);
    store::setFileOperationHook([&](const char*, const std::string&) { ++operations; });
    bake(dir, resumeCity().view_space, false);
    store::setFileOperationHook({});
  }
  ASSERT_GT(operations, 20u);

  for (const double at : {0.15, 0.6, 0.97}) {
    SCOPED_TRACE("crash at " + std::to_string(at));
    const std::string dir = test::scratchDir("resume_crash").string();
    bake(dir, resumeCity().earlier, false);
    const nlohmann::json before = store::comparableRecords(store::readIndex(dir));
    const size_t crash_at = size_t(at * double(operations));
    size_t n = 0;
    bool old_readable = true, replaced = false;
    store::setFileOperationHook([&](const char* operation, const std::string& path) {
      // The database in the directory is the earlier one, whole, until the new index is renamed into place.
      if (std::string(operation) == "rename" && fs::path(path).filename() == store::kIndexFile) replaced = true;
      if (!replaced && n % 7 == 0) {
        try {
          if (store::comparableRecords(store::readIndex(dir)) != before) old_readable = false;
        } catch (const Error&) {
          old_readable = false;
        }
      }
      if (++n == crash_at) throw Crash{};
    });
    bool crashed = false;
    try {
      bake(dir, resumeCity().view_space, false);
    } catch (const Crash&) {
      crashed = true;
    }
    store::setFileOperationHook({});
    EXPECT_TRUE(crashed);
    EXPECT_TRUE(old_readable);
    // What the journal finished survives the crash and is kept.
    std::set<uint32_t> journaled;
    if (const auto journal = store::readJournal(dir))
      for (const nlohmann::json& c : journal->cells) journaled.insert(c["half_edge"].get<uint32_t>());
    const PipelineReport resumed = bake(dir, resumeCity().view_space, true);
    EXPECT_EQ(resumed.resumed, journaled.size());
    EXPECT_EQ(resumed.resume_rejected, 0u);
    EXPECT_EQ(resumed.cells.size(), resumeCity().view_space.size());
    EXPECT_EQ(store::firstDifference(store::comparableRecords(store::readIndex(dir)), expected), "");
    EXPECT_FALSE(fs::exists(fs::path(dir) / store::kJournalFile));
    // Resuming a finished bake does nothing.
    EXPECT_TRUE(bake(dir, resumeCity().view_space, true).already_complete);
  }
}

// The first mesh file a cell record names.
std::string firstMesh(const nlohmann::json& j) {
  if (j.is_object()) {
    if (j.contains("mesh") && j["mesh"].is_string() && !j["mesh"].get<std::string>().empty())
      return j["mesh"].get<std::string>();
    for (const auto& [key, value] : j.items())
      if (std::string m = firstMesh(value); !m.empty()) return m;
  }
  if (j.is_array())
    for (const nlohmann::json& e : j)
      if (std::string m = firstMesh(e); !m.empty()) return m;
  return "";
}

TEST(BakeResumeTest, AJournalOfAnotherBakeIsAnErrorAndARejectedCellIsBakedAgain) {
  const std::string dir = test::scratchDir("resume_other").string();
  size_t n = 0;
  store::setFileOperationHook([&](const char* operation, const std::string&) {
    if (std::string(operation) == "rename" && ++n == 40) throw Crash{};
  });
  EXPECT_THROW(bake(dir, resumeCity().view_space, false), Crash);
  store::setFileOperationHook({});
  const auto journal = store::readJournal(dir);
  ASSERT_TRUE(journal);
  ASSERT_FALSE(journal->cells.empty());
  // Another cell list is another bake.
  try {
    bake(dir, {resumeCity().view_space[0], resumeCity().view_space[1]}, true);
    ADD_FAILURE() << "expected an error for a journal of another bake";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bake.journal"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("todo"), std::string::npos) << e.what();
  }
  // A finished cell whose file was damaged after the crash is baked again, not trusted.
  const std::string mesh = firstMesh(journal->cells[0]);
  ASSERT_FALSE(mesh.empty());
  fs::resize_file(fs::path(dir) / mesh, 10);
  const PipelineReport r = bake(dir, resumeCity().view_space, true);
  EXPECT_EQ(r.resume_rejected, 1u);
  EXPECT_EQ(r.resumed, journal->cells.size() - 1);
  const std::string reference = test::scratchDir("resume_other_reference").string();
  bake(reference, resumeCity().view_space, false);
  EXPECT_EQ(store::firstDifference(store::comparableRecords(store::readIndex(dir)),
                                   store::comparableRecords(store::readIndex(reference))),
            "");
}

}  // namespace
}  // namespace farfield::bake
