// The placement database of `farfield place` (store/placement_store.h): a crafted placement.json and its layer images
// in the container of store_container.h. The index is read with readPlacementIndex (checksum, text form, the BSP and
// CPV rules, each impostor's plan inputs), every impostor is loaded (plan re-derived, images checked against it), and
// the CPV lookup runs at a few points of the view space.
#include <algorithm>
#include <filesystem>

#include "farfield/store/placement_store.h"
#include "store_container.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const fuzz::StoreInput in = fuzz::splitStoreInput(data, size);
  const std::filesystem::path dir = fuzz::freshDirectory("placement");
  fuzz::writeStore(in, dir, store::kPlacementIndexFile, [](nlohmann::json& j) {
    j.erase("checksum");
    return store::placementFileText(j);
  });
  fuzz::expectFarfieldErrors([&] {
    const store::PlacementIndex index = store::readPlacementIndex(dir.string());
    for (size_t i = 0; i < index.impostors.size() && i < 8; ++i)
      store::loadPlacedImpostor(dir.string(), index.impostors[i]);
    const Box3& b = index.view_space;
    for (int k = 0; k < 27; ++k) {
      const Vec3 t(float(k % 3) * 0.5f, float(k / 3 % 3) * 0.5f, float(k / 9) * 0.5f);
      const Vec3 eye = b.lo + (b.hi - b.lo) * t;
      store::lookupCpv(index, eye, Vec3(1.0f, float(k % 5) - 2.0f, 0.25f * float(k % 3) - 0.25f));
    }
  });
  return 0;
}
