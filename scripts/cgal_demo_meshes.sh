# Sourced by fetch_meshes.sh and fetch_corpus.sh: obtains meshes of CGAL's
# demo data (data/meshes in the data.tar.gz of Debian's libcgal-demo package),
# verifies their SHA-256 and caches them in a folder.
#   declare -A SHA=([name.off]=sha256 ...)
#   fetch_cgal_demo_meshes OUT_DIR "what, for the messages"
# Idempotent: returns at once when OUT_DIR already holds the verified files.

cgal_demo_meshes_verified() {
  local out="$1" f
  for f in "${!SHA[@]}"; do
    [ -f "$out/$f" ] || return 1
    echo "${SHA[$f]}  $out/$f" | sha256sum --quiet -c - >/dev/null 2>&1 || return 1
  done
}

fetch_cgal_demo_meshes() {
  local out="$1" what="$2" tmp deb f got
  mkdir -p "$out"
  cgal_demo_meshes_verified "$out" && return 0
  echo "[icd] fetching $what from Debian's libcgal-demo"
  tmp=$(mktemp -d)
  # shellcheck disable=SC2064  # expand $tmp now: it is local
  trap "rm -rf '$tmp'" EXIT
  chmod 755 "$tmp"
  (cd "$tmp" && apt-get download libcgal-demo >/dev/null 2>&1) || {
    local SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -qq && (cd "$tmp" && apt-get download libcgal-demo >/dev/null)
  }
  deb=$(ls "$tmp"/libcgal-demo_*.deb)
  dpkg -x "$deb" "$tmp/x"
  local members=()
  for f in "${!SHA[@]}"; do members+=("data/meshes/$f"); done
  tar -xzf "$tmp/x/usr/share/doc/libcgal-dev/data.tar.gz" -C "$tmp" "${members[@]}"
  for f in "${!SHA[@]}"; do
    got=$(sha256sum "$tmp/data/meshes/$f" | cut -d' ' -f1)
    if [ "$got" != "${SHA[$f]}" ]; then
      echo "[icd] checksum mismatch for $f: got $got, expected ${SHA[$f]}" >&2
      exit 1
    fi
    # Write under a temporary name, then rename: no half-written mesh.
    cp "$tmp/data/meshes/$f" "$out/$f.part" && mv "$out/$f.part" "$out/$f"
  done
  echo "[icd] ${#SHA[@]} meshes cached in $out"
}
