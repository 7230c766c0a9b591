#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (address and undefined-behaviour sanitizers) into
# build-fuzz/ and runs each for SECONDS (default 20), starting from real files as seeds. A crash,
# a sanitizer report or a hang fails the script and leaves the input in build-fuzz/findings/.
# Usage: scripts/fuzz.sh [SECONDS] [SEED]. With a SEED the mutations are the same every run (CI
# uses one, so that a landing does not depend on luck); without one each run explores anew.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
seed_option=()
if [ $# -ge 2 ]; then seed_option=(-seed="$2"); fi

if [ ! -f build-fuzz/CMakeCache.txt ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTAIGA_BUILD_FUZZERS=ON -DTAIGA_BUILD_TESTS=OFF > /dev/null
fi
targets=$(find fuzz -name 'fuzz_*.cpp' | xargs -n1 basename | sed 's/\.cpp$//' | sort)
cmake --build build-fuzz --parallel "$(nproc)" --target $targets

seed() {  # seed corpus of a target: small real files it should parse
  local corpus=build-fuzz/corpus/$1
  mkdir -p "$corpus"
  case $1 in
    fuzz_cloud_files)
      printf '\000FIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\nWIDTH 2\nPOINTS 2\nDATA ascii\n1 2 3 0\n4 5 6 100\n' > "$corpus/ascii_pcd"
      printf '\001ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n' > "$corpus/ascii_ply"
      { printf '\001'; head -c 2000 ../shared/data/registration/source.ply; } > "$corpus/binary_ply" 2>/dev/null || true ;;
    fuzz_keyframe_files)
      # A keyframe file of two points with every channel, and a LAS file of one point.
      printf '\000TAIGAKF1\001\000\000\000\017\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\360\077\002\000\000\000\000\000\000\000' > "$corpus/keyframe"
      head -c 80 /dev/zero >> "$corpus/keyframe"
      /usr/bin/python3 -c 'import struct,sys
h=bytearray(375); h[0:4]=b"LASF"; h[24]=1; h[25]=4; struct.pack_into("<HIIBHI",h,94,375,375,0,6,30,0)
struct.pack_into("<3d3d",h,131,.001,.001,.001,0,0,0); struct.pack_into("<Q",h,247,1)
sys.stdout.buffer.write(b"\x01"+bytes(h)+struct.pack("<3iH4BhHd",1000,2000,3000,7,17,0,1,5,0,3,1.7e9))' > "$corpus/las" ;;
    fuzz_ouster_packets)
      for json in ../shared/data/ouster/*.json; do
        [ -f "$json" ] && { printf '\000'; cat "$json"; } > "$corpus/$(basename "$json")"
      done
      head -c 4096 /dev/zero | tr '\000' '\001' > "$corpus/packets"
      # Live datagrams (selector 1): a 304-byte lidar packet (type 1) and a 48-byte IMU packet of
      # the fuzz target's small sensor, each after its 2-byte length.
      /usr/bin/python3 -c 'import struct,sys
lidar=bytearray(304); lidar[0]=1; imu=bytearray(48)
sys.stdout.buffer.write(b"\x01"+struct.pack("<H",304)+bytes(lidar)+struct.pack("<H",48)+bytes(imu))' > "$corpus/live" ;;
    fuzz_trees_csv)
      printf 'id,x_m,y_m,z_m,dbh_m,height_m,lean_deg,lean_azimuth_deg,species,x_bh_m,y_bh_m\n0,3.1,24.2,-0.26,0.265,19.2,1.8,313.6,pine,3.17,24.14\n' > "$corpus/simulator"
      printf 'id,x_m,y_m,z_m,x_bh_m,y_bh_m,dbh_m,dbh_sigma_m,height_m,lean_deg,lean_azimuth_deg,points,fit_rms_m,arc_deg,slices,quality\n1,-40.1,-7.5,0.37,-40.2,-7.6,0.159,0.013,15.33,3.61,211.3,24,0.0153,150,4,partial\n' > "$corpus/taiga" ;;
  esac
  echo "$corpus"
}

mkdir -p build-fuzz/findings
for target in $targets; do
  echo "fuzz: $target for $seconds s"
  corpus=$(seed "$target")
  build-fuzz/bin/$target "$corpus" "${seed_option[@]}" -max_total_time="$seconds" -timeout=10 -max_len=65536 -rss_limit_mb=2048 -print_final_stats=0 \
    -artifact_prefix=build-fuzz/findings/"$target"- 2>&1 | tail -n 3
done
echo "fuzz: no crash in $(echo $targets | wc -w) targets"
