#!/usr/bin/env bash
# Obtains the paper's real meshes (Stanford bunny, Chinese dragon) from Debian's
# libcgal-demo package, verifies their checksums and caches them in data/.
# Idempotent: does nothing when data/ already holds the verified files.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
data="$root/data"
mkdir -p "$data"

declare -A SHA=(
  [bunny00.off]=ab651cb04955c161efaeb079035a1e5e1f0e0d1f816a2df67beaea68f393ff2b
  [ChineseDragon-10kv.off]=f633bdfaac7a0f99e0fab668c34862f0c26f341cfdb4665bab282d79b788db02
)

verified() {
  local f
  for f in "${!SHA[@]}"; do
    [ -f "$data/$f" ] || return 1
    echo "${SHA[$f]}  $data/$f" | sha256sum --quiet -c - >/dev/null 2>&1 || return 1
  done
}
verified && exit 0

echo "[icd] fetching the bunny and dragon meshes from Debian's libcgal-demo"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
chmod 755 "$tmp"
(cd "$tmp" && apt-get download libcgal-demo >/dev/null 2>&1) || {
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq && (cd "$tmp" && apt-get download libcgal-demo >/dev/null)
}
deb=$(ls "$tmp"/libcgal-demo_*.deb)
dpkg -x "$deb" "$tmp/x"
tar -xzf "$tmp/x/usr/share/doc/libcgal-dev/data.tar.gz" -C "$tmp" \
  data/meshes/bunny00.off data/meshes/ChineseDragon-10kv.off
for f in "${!SHA[@]}"; do
  got=$(sha256sum "$tmp/data/meshes/$f" | cut -d' ' -f1)
  if [ "$got" != "${SHA[$f]}" ]; then
    echo "[icd] checksum mismatch for $f: got $got, expected ${SHA[$f]}" >&2
    exit 1
  fi
  # Write under a temporary name, then rename: no half-written mesh in data/.
  cp "$tmp/data/meshes/$f" "$data/$f.part" && mv "$data/$f.part" "$data/$f"
done
echo "[icd] meshes cached in $data"
