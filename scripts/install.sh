#!/usr/bin/env bash
# Installs the C library that `cargo build --release -p kage` made under PREFIX:
#   PREFIX/include/kage.h
#   PREFIX/lib/libkage.so.N          the shared library under its SONAME (N: the ABI version),
#                                    the name the loader looks for when a host starts
#   PREFIX/lib/libkage.so -> .so.N   the name `-lkage` finds when a host links
#   PREFIX/lib/libkage.a             the static library
# Usage: bash scripts/install.sh PREFIX   (CARGO_TARGET_DIR is honoured, as cargo does)
set -euo pipefail
if [ $# -ne 1 ] || [ -z "$1" ]; then
  echo "usage: bash scripts/install.sh PREFIX" >&2
  exit 2
fi
prefix=$1
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
built=${CARGO_TARGET_DIR:-$repo/target}/release
header=$repo/engine/include/kage.h
for file in "$built/libkage.so" "$built/libkage.a"; do
  if [ ! -f "$file" ]; then
    echo "install.sh: $file is missing: run \`cargo build --release -p kage\` first" >&2
    exit 1
  fi
done
soname=$(readelf -d "$built/libkage.so" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
# The committed header and the built library must name the same ABI: a library built before
# the header changed would be installed under a name the header's hosts do not expect.
abi=$(sed -n 's/^ *KAGE_ABI_VERSION = \([0-9]*\),$/\1/p' "$header")
if [ "$soname" != "libkage.so.$abi" ]; then
  echo "install.sh: $built/libkage.so is named '$soname' but kage.h declares ABI $abi: rebuild with \`cargo build --release -p kage\`" >&2
  exit 1
fi
install -D -m 644 "$header" "$prefix/include/kage.h"
install -D -m 755 "$built/libkage.so" "$prefix/lib/$soname"
ln -sfn "$soname" "$prefix/lib/libkage.so"
install -D -m 644 "$built/libkage.a" "$prefix/lib/libkage.a"
echo "installed kage.h, $soname (libkage.so links to it) and libkage.a under $prefix"
