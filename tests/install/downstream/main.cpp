// Loads an asset bundle, collides two copies of it under a budget of sphere
// tests, then steps a two-object simulation: the library used from outside.
// Usage: downstream BUNDLE_FOLDER
#include <cstdio>
#include <exception>
#include <vector>

#include <icd/collision/traversal.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: downstream BUNDLE_FOLDER\n");
    return 2;
  }
  try {
    icd::coupling::AssetBundle bundle = icd::coupling::read_asset_bundle(argv[1]);
    if (bundle.spheres.num_nodes() == 0) icd::coupling::build_octree_spheres(bundle, 3);

    // Two copies 0.3 m long, overlapping by a fifth of their length.
    std::vector<icd::coupling::WorldObject> objects(2);
    for (int i = 0; i < 2; ++i) {
      objects[i].setup.name = i ? "right" : "left";
      objects[i].setup.material.young = 3e5;
      objects[i].setup.velocity = {i ? -0.2 : 0.2, 0, 0};
      objects[i].asset = bundle;
      icd::coupling::place_asset(objects[i].asset, {0.3, {i ? 0.12 : -0.12, 0, 0}, {0, 0, 0}});
    }

    icd::collision::CollisionRequest request;
    request.budget_tests = 5000;
    const icd::collision::CollisionResult r = icd::collision::collide(
        objects[0].asset.spheres, objects[1].asset.spheres, request);
    std::printf("collide: %lld tests, %zu colliding leaf pairs, %zu untested, interrupted %d\n",
                static_cast<long long>(r.tests), r.colliding.size(), r.untested.size(),
                r.interrupted ? 1 : 0);
    if (r.tests > 5000 || r.colliding.size() + r.untested.size() == 0) return 1;

    icd::coupling::WorldSettings settings;
    settings.collision.query.budget_tests = 5000;
    icd::coupling::World world(std::move(objects), settings);
    int contact_frames = 0;
    for (int f = 0; f < 10; ++f) contact_frames += world.step().active_pairs > 0;
    std::printf("world: 10 frames, %d with contact forces\n", contact_frames);
    return contact_frames > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "downstream: %s\n", e.what());
    return 1;
  }
}
