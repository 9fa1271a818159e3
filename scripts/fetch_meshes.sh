#!/usr/bin/env bash
# Obtains the paper's real meshes (Stanford bunny, Chinese dragon) from Debian's
# libcgal-demo package, verifies their checksums and caches them in data/.
# Idempotent: does nothing when data/ already holds the verified files.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
data="$root/data"

declare -A SHA=(
  [bunny00.off]=ab651cb04955c161efaeb079035a1e5e1f0e0d1f816a2df67beaea68f393ff2b
  [ChineseDragon-10kv.off]=f633bdfaac7a0f99e0fab668c34862f0c26f341cfdb4665bab282d79b788db02
)

. "$root/scripts/cgal_demo_meshes.sh"
fetch_cgal_demo_meshes "$data" "the bunny and dragon meshes"
