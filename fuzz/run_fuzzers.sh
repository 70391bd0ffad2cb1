#!/usr/bin/env bash
# Runs every fuzz target of a WAVETRACE_FUZZ build from the committed seed corpus, two at a
# time (FUZZ_JOBS sets how many), and prints each target's executions and findings; exits
# non-zero if any target found one.
#   fuzz/run_fuzzers.sh BUILD_DIR 60s          # a minute each (CI's smoke run)
#   fuzz/run_fuzzers.sh BUILD_DIR 10000000     # ten million executions each
# New inputs go to BUILD_DIR/fuzz-corpus/TARGET, findings to BUILD_DIR/fuzz-findings/.
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:?usage: run_fuzzers.sh BUILD_DIR SECONDSs|RUNS [TARGET...]}
limit=${2:?usage: run_fuzzers.sh BUILD_DIR SECONDSs|RUNS [TARGET...]}
shift 2
targets=("$@")
((${#targets[@]})) || targets=(mesh_off mesh_ply mesh_obj mesh_stl scene_file config world_file)
if [[ $limit == *s ]]; then budget="-max_total_time=${limit%s}"; else budget="-runs=$limit"; fi
# FUZZ_MAX_SECONDS caps a run of RUNS executions; FUZZ_MAX_LEN bounds the inputs of the text
# targets (a world file is ~100 KB and gets 256 KiB).
[[ -n ${FUZZ_MAX_SECONDS:-} && $limit != *s ]] && budget="$budget -max_total_time=$FUZZ_MAX_SECONDS"
text_max_len=${FUZZ_MAX_LEN:-4096}
mkdir -p "$build/fuzz-findings" "$build/fuzz-logs"

# World files are build outputs (and 100 KB each), so their seeds are built here rather
# than committed: one small world per saved layout, and one rebuilt from its mesh (embree).
make_world_seeds() {
  local seeds="$build/fuzz-seeds/world_file" accel
  mkdir -p "$seeds"
  for accel in bvh bvh:width=8 hmq hmq:width=8 hmq:epsilon=0.01 hmq8_together raystrips raystrips:width=8 embree chunked proxy; do
    local name=${accel//[:=]/_} scene=builtin:sphere:600 options=()
    case $accel in
      hmq8_together) options=(--accel hmq:width=8:leaves_beside_nodes=true) ;;
      *:*) options=(--accel "${accel%%:*}" --set "accel.${accel%%:*}.${accel#*:}") ;;
      chunked) scene=builtin:sphere:2500 options=(--accel hmq --set build.chunk_triangles=1024) ;;
      proxy) options=(--accel bvh --proxy) ;;
      *) options=(--accel "$accel") ;;
    esac
    [[ -f $seeds/$name.wtw ]] || "$build/wavetrace" build "$scene" "${options[@]}" --out "$seeds/$name.wtw" >/dev/null
  done
}

run_one() {
  local target=$1 seeds
  seeds="$root/fuzz/corpus/${target#mesh_}"
  [[ $target == world_file ]] && seeds="$build/fuzz-seeds/world_file"
  mkdir -p "$build/fuzz-corpus/$target"
  # -timeout: an input taking 10 s is a hang; -rss_limit_mb: one using 2 GB is a leak or
  # an unbounded allocation; both are findings, as crashes and sanitizer reports are.
  # shellcheck disable=SC2086  # $budget is one or two flags
  "$build/fuzz/fuzz_$target" "$build/fuzz-corpus/$target" "$seeds" $budget -timeout=10 -rss_limit_mb=2048 \
    -max_len=$([[ $target == world_file ]] && echo 262144 || echo "$text_max_len") -print_final_stats=1 -artifact_prefix="$build/fuzz-findings/$target-" \
    > "$build/fuzz-logs/$target.log" 2>&1
  local status=$?
  local runs seconds
  runs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$build/fuzz-logs/$target.log" | grep -o '[0-9]*$')
  seconds=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$build/fuzz-logs/$target.log" | grep -o 'in [0-9]*' | grep -o '[0-9]*')
  if ((status == 0)); then
    echo "fuzz_$target: ${runs:-?} executions in ${seconds:-?} s, no findings"
  else
    echo "fuzz_$target: FINDING (exit $status) after ${runs:-?} executions; see $build/fuzz-logs/$target.log"
    grep -m3 -E 'ERROR|runtime error|SUMMARY|Test unit written' "$build/fuzz-logs/$target.log" | sed 's/^/  /'
  fi
  return $status
}
[[ " ${targets[*]} " == *" world_file "* ]] && make_world_seeds
export -f run_one
export root build budget text_max_len
printf '%s\n' "${targets[@]}" | xargs -P "${FUZZ_JOBS:-2}" -I{} bash -c 'run_one {}'
