#!/usr/bin/env bash
# Every reader of a file goes through the checked opener (core/include/dualgrid/core/input_file.hpp:
# regular files only, bounded, a clear line for FIFOs, devices, folders and link loops). This
# check fails when a source file outside tests/ opens a file for reading another way: a raw
# std::ifstream, fopen, open, gzopen or H5Fopen not listed below with the reason it is safe.
# Usage: check_raw_opens.sh REPO
set -uo pipefail
repo=$1
# path:text-of-the-line — each with why it may open the file directly.
allowed=(
  # The checked opener itself.
  "core/src/input_file.cpp:open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)"
  # HDF5 opens by name: CheckInputFile (regular, readable, no loop) runs just before.
  "recorded/src/radarscenes_read.cpp:H5Fopen(h5_name.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)"
  # Logs our own child processes (SUMO, netconvert, ffmpeg) just wrote into our output folder.
  "sim/src/sumo_tools.cpp:std::ifstream in(log)"
  "tools/src/child_process.cpp:std::ifstream in(p)"
  "outputs/src/video.cpp:std::ifstream in(log_)"
  # The kernel's file about this process.
  "outputs/src/run_observers.cpp:std::ifstream in(\"/proc/self/statm\")"
  # Files of the run folder this process wrote, hashed byte for byte (compressed as written).
  "outputs/src/run_folder.cpp:std::ifstream in(f, std::ios::binary)"
  # frames.bin, read at offsets: the replay Reader's constructor checked it (regular file, size)
  # with the checked opener's rules; a later change is reported by name.
  "outputs/src/recording.cpp:std::ifstream in(dir_ / \"frames.bin\", std::ios::binary)"
)
cd "$repo" || exit 2
failed=0
while IFS= read -r hit; do
  file=${hit%%:*}
  rest=${hit#*:}
  line=${rest#*:}
  # Comments, open() for writing (O_WRONLY) and fopen/gzopen in a write or append mode ("w...",
  # "a..."): writers, not readers.
  [[ "$line" =~ ^[[:space:]]*// || "$line" == *O_WRONLY* ]] && continue
  [[ "$line" =~ (fopen|gzopen)\(.*,\ *\"[wa][^\"]*\"\) ]] && continue
  ok=0
  for a in "${allowed[@]}"; do
    [[ "$file" == "${a%%:*}" && "$line" == *"${a#*:}"* ]] && ok=1 && break
  done
  if [ "$ok" -eq 0 ]; then
    echo "FAIL $file: opens a file outside the checked opener: $(echo "$line" | sed 's/^ *//')"
    failed=$((failed + 1))
  fi
done < <(grep -rnE 'std::ifstream|std::fstream|\bfopen\(|\bgzopen\(|\bH5Fopen\(|[^_a-zA-Z.>]open\(' \
           --include='*.cpp' --include='*.hpp' --include='*.h' \
           core filter radar_model sim scenarios eval viz cosim recorded outputs tools python/src)
[ "$failed" -eq 0 ] && echo "every reader goes through the checked opener (${#allowed[@]} allowed exceptions)"
exit $((failed > 0))
