// The impostor database of `farfield bake` (store/impostor_store.h, store/cell_reader.h): a crafted index and its
// records (street graph, meshes, textures, object ids) in the container of store_container.h. The index is read with
// readIndex (checksum, text form, every rule of every version 1-4), then each cell's views with readCellViews or,
// with the MODE bit kThreadedReader, with the prefetching store::CellReader, and every Sillion impostor with
// loadImpostor.
#include <algorithm>
#include <filesystem>

#include "farfield/store/cell_reader.h"
#include "farfield/store/impostor_store.h"
#include "store_container.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const fuzz::StoreInput in = fuzz::splitStoreInput(data, size);
  const std::filesystem::path dir = fuzz::freshDirectory("store");
  fuzz::writeStore(in, dir, store::kIndexFile, [](nlohmann::json& j) { return store::indexFileText(j); });
  fuzz::expectFarfieldErrors([&] {
    const store::StoreIndex index = store::readIndex(dir.string());
    const size_t cells = std::min<size_t>(index.cells.size(), 8);
    if (in.mode & fuzz::kThreadedReader) {
      store::CellReader::Options o;
      o.single = true;
      o.budget_bytes = 1 << 20;
      store::CellReader reader(dir.string(), index, o);
      for (size_t c = 0; c < cells; ++c) reader.prefetch(index.cells[c].half_edge);
      for (size_t c = 0; c < cells; ++c)
        if (index.cells[c].pipeline) reader.take(index.cells[c].half_edge);
    } else {
      for (size_t c = 0; c < cells; ++c)
        if (index.cells[c].pipeline) store::readCellViews(dir.string(), index, index.cells[c].half_edge, true, true);
    }
    for (size_t c = 0; c < cells; ++c)
      for (const auto& [technique, impostor] : index.cells[c].impostors)
        store::loadImpostor(dir.string(), index.cells[c], technique);
  });
  return 0;
}
