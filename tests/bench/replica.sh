#!/usr/bin/env bash
# A K-times replica of a folder of BVH clips, for the scale figures of issue 16:
#   tests/bench/replica.sh SRC DST [K=25]
# writes DST/rNN/rNN_<stem>.bvh for NN = 01..K. Copies, not links: the build reads a file
# reached twice through links (same device and inode) only once. Use a scratch folder
# (/tmp), never the repository; about K × the size of SRC.
set -euo pipefail
src=${1:?usage: replica.sh SRC DST [K]}
dst=${2:?usage: replica.sh SRC DST [K]}
k=${3:-25}
mkdir -p "$dst"
for n in $(seq -w 1 "$k"); do
  mkdir -p "$dst/r$n"
  find -L "$src" -name '*.bvh' -type f | while read -r f; do
    b=$(basename "$f")
    cp --reflink=auto "$f" "$dst/r$n/r${n}_$b"
  done
done
echo "$(find "$dst" -name '*.bvh' | wc -l) clips in $dst"
