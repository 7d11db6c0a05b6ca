#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Accuracy benchmark of issue 13, section 5: where the project stands on scenes that look like the world.
# Run by hand (not by .ci/run, not a ctest test); it neither installs nor builds: build first with
# `cmake --build build`. It synthesises the whole development set (every scenario of
# `dynvo_synthesize -list`, realistic depth noise, one fixed seed), composites every object scenario into
# each real recording of a static scene, tum_fr1_xyz_200 and tum_fr1_desk_fast (when dynvo_synthesize has
# -composite), the scenarios of PLAIN_SCENARIOS once more with -plain_objects (one flat colour per face:
# rows RECORDING+SCENARIO+plain_objects), and adds the real recordings tum_fr1_xyz_200, tum_fr1_desk_fast and bonn_crowd_people
# (people walking: no truth masks, so its moving_share is the share of pixels labelled moving, not an
# error) as they are, each with its own intrinsics, and once more at 15 Hz (rows RECORDING@15Hz: every
# other colour frame over the same span, so twice the motion between frames, as a slower camera or
# dropped frames give). On each sequence it runs dynvo_odometry with
# -labels_dir and -bench_reference cv_rgbd (OpenCV's RGB-D odometry over the whole image on the same
# frames: column "RPE cv_rgbd") and again with -no_segmentation, scores trajectories and labels with
# dynvo_evaluate, and prints one markdown table (also written to <work>/table.md). Sequences run one
# after the other; about 200 MB of disk per 300-frame sequence.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"  # ROOT, BUILD and say (defines functions only)

usage() {
  cat <<EOF
Usage: scripts/bench_accuracy.sh [-frames N] [-only NAME[,NAME...]] [-work DIR] [-seed S] [-force]

  -frames N    frames per synthetic sequence (default 300, at least 31: RPE uses a 1 s delta);
               composites and the real recordings use min(N, the recording's frame count)
  -only LIST   comma-separated rows to run: a scenario name selects its synthetic sequence and
               its composites, RECORDING+NAME only that composite (RECORDING: $(commas $(composite_hosts))),
               RECORDING+NAME+plain_objects its plain-object composite (NAME: $(commas "${PLAIN_SCENARIOS[@]}")),
               RECORDING the real recording as it is ($(commas "${REALS[@]}")),
               RECORDING@15Hz every other colour frame of it
               (default: everything)
  -work DIR    work folder (default \$DYNVO_BENCH_WORK or $BUILD/bench_accuracy); it must be
               empty or absent
  -force       reuse a work folder of an earlier run: deletes only its own synthetic/,
               composite/, halfrate/, runs/ and table.md
  -seed S      seed of every synthesised sequence and of dynvo_odometry (default 0)

Environment: DYNVO_BUILD_DIR (default <repo>/build), DYNVO_SHARED_DATA_DIR (default
<repo>/../shared/data), DYNVO_BENCH_WORK.
EOF
}

die() { printf '\nbench_accuracy.sh: error: %s\n' "$*" >&2; exit 1; }

# --- real recordings (DYNVO_SHARED_DATA_DIR, see its README.md) and their intrinsics flags ---
REALS=(tum_fr1_xyz_200 tum_fr1_desk_fast bonn_crowd_people)
declare -A CAMERA=(
  [tum_fr1_xyz_200]="-camera fr1"
  [tum_fr1_desk_fast]="-camera fr1"
  [bonn_crowd_people]="-fx 542.822841 -fy 542.576870 -cx 315.593520 -cy 237.756098"
)
# 1: a static scene, into which the object scenarios are composited and which is scored by
# moving_share (should be near 0); 0: a scene with its own movers.
declare -A STATIC_SCENE=([tum_fr1_xyz_200]=1 [tum_fr1_desk_fast]=1 [bonn_crowd_people]=0)
# Composited once more with -plain_objects: a box Lucas-Kanade finds nothing to track inside.
PLAIN_SCENARIOS=(moving_crossing)
composite_hosts() { local r; for r in "${REALS[@]}"; do [ "${STATIC_SCENE[$r]}" = 0 ] || echo "$r"; done; }
commas() { local list; list="$(printf '%s, ' "$@")"; printf '%s' "${list%, }"; }  # "a, b, c"

FRAMES=300
SEED=0
ONLY=""
FORCE=0
WORK="${DYNVO_BENCH_WORK:-$BUILD/bench_accuracy}"
while [ $# -gt 0 ]; do
  case "$1" in
    -frames) [ $# -ge 2 ] || die "-frames needs a value"; FRAMES="$2"; shift 2 ;;
    -only)   [ $# -ge 2 ] || die "-only needs a value"; ONLY="$2"; shift 2 ;;
    -work)   [ $# -ge 2 ] || die "-work needs a value"; WORK="$2"; shift 2 ;;
    -seed)   [ $# -ge 2 ] || die "-seed needs a value"; SEED="$2"; shift 2 ;;
    -force)  FORCE=1; shift ;;
    -h|-help|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument '$1'" ;;
  esac
done
[[ "$FRAMES" =~ ^[0-9]+$ ]] && [ "$FRAMES" -ge 31 ] ||
  die "-frames must be an integer of at least 31 (RPE pairs frames 1 s apart at 30 Hz), got '$FRAMES'"
[[ "$SEED" =~ ^[0-9]+$ ]] || die "-seed must be a non-negative integer, got '$SEED'"

BIN="$BUILD/bin"
SYNTH="$BIN/dynvo_synthesize"
ODOM="$BIN/dynvo_odometry"
EVAL="$BIN/dynvo_evaluate"
for b in "$SYNTH" "$ODOM" "$EVAL"; do
  [ -x "$b" ] || die "missing $b: build first: cmake --build ${BUILD#"$PWD"/}"
done

DATA="${DYNVO_SHARED_DATA_DIR:-$ROOT/../shared/data}"
[ ! -d "$DATA" ] || DATA="$(cd "$DATA" && pwd)"

# --- scenarios: "name  share %  description" after '#' header lines ---
LIST_OUT="$("$SYNTH" -list)" || die "dynvo_synthesize -list failed (exit $?)"
SCENARIOS=()
declare -A HAS_OBJECT=()
while read -r name share _; do
  [ -n "$name" ] || continue
  SCENARIOS+=("$name")
  # Object scenarios (all that can be composited): a largest moving-pixel share above 0.
  HAS_OBJECT[$name]=$(awk -v s="$share" 'BEGIN { print (s + 0 > 0) ? 1 : 0 }')
done < <(grep -v '^#' <<<"$LIST_OUT")
[ ${#SCENARIOS[@]} -gt 0 ] || die "dynvo_synthesize -list printed no scenario"

# --- -only ---
declare -A WANT=()
if [ -n "$ONLY" ]; then
  IFS=',' read -r -a only_names <<<"$ONLY"
  for n in "${only_names[@]}"; do
    known=0
    [[ " ${SCENARIOS[*]} " != *" $n "* ]] || known=1
    [[ " ${REALS[*]} " != *" $n "* ]] || known=1
    recording="${n%@15Hz}"
    if [ "$recording" != "$n" ] && [[ " ${REALS[*]} " == *" $recording "* ]]; then known=1; fi
    for host in $(composite_hosts); do
      base="${n#"$host"+}"
      if [ "$base" != "$n" ] && [ "${HAS_OBJECT[$base]:-0}" = 1 ]; then known=1; fi
      plain="${base%+plain_objects}"
      if [ "$base" != "$n" ] && [ "$plain" != "$base" ] &&
         [[ " ${PLAIN_SCENARIOS[*]} " == *" $plain "* ]]; then known=1; fi
    done
    [ "$known" = 1 ] ||
      die "-only: '$n' is neither a scenario of dynvo_synthesize -list, a real recording" \
          "($(commas "${REALS[@]}"), or RECORDING@15Hz) nor RECORDING+SCENARIO with an object scenario and RECORDING" \
          "one of $(commas $(composite_hosts)) (or RECORDING+SCENARIO+plain_objects, SCENARIO one of" \
          "$(commas "${PLAIN_SCENARIOS[@]}"))"
    WANT[$n]=1
  done
fi
selected() {  # row label [scenario whose name also selects the row]
  [ -z "$ONLY" ] || [ -n "${WANT[$1]:-}" ] || { [ $# -ge 2 ] && [ -n "${WANT[$2]:-}" ]; }
}

# --- work folder: never delete anything but our own subfolders, and only in our own folder ---
MARK=".dynvo_bench_accuracy"
if [ -d "$WORK" ] && [ -n "$(ls -A "$WORK")" ]; then
  [ "$FORCE" -eq 1 ] || die "work folder $WORK is not empty: pass -force to reuse it, or -work DIR"
  [ -e "$WORK/$MARK" ] ||
    die "work folder $WORK is not empty and was not made by bench_accuracy.sh (no $MARK): refusing to clean it"
  say "Reusing $WORK: deleting its synthetic/, composite/, halfrate/, runs/ and table.md"
  rm -rf -- "$WORK/synthetic" "$WORK/composite" "$WORK/halfrate" "$WORK/runs" "$WORK/table.md"
fi
mkdir -p "$WORK/synthetic" "$WORK/composite" "$WORK/halfrate" "$WORK/runs"
touch "$WORK/$MARK"
WORK="$(cd "$WORK" && pwd)"

T_START=$SECONDS
git_state() {  # short commit, "+local changes" when tracked files differ from it
  local c
  c="$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  [ -z "$(git -C "$ROOT" status --porcelain --untracked-files=no 2>/dev/null)" ] || c="$c+local changes"
  printf '%s' "$c"
}
bins_stamp() { stat -c '%Y' "$SYNTH" "$ODOM" "$EVAL" | tr '\n' ' '; }
COMMIT="$(git_state)"
BINS_AT_START="$(bins_stamp)"
ROWS=()
FAILED=()

kv() { tr ' ' '\n' <<<"$2" | sed -n "s/^$1=//p" | head -n 1; }  # value of KEY in "k=v k=v ..."
fmt() {  # DECIMALS VALUE: '–' when absent, nan as is
  if [ -z "$2" ]; then printf -- '–'
  elif [[ "$2" =~ ^[-+0-9.eE]+$ ]]; then printf "%.${1}f" "$2"
  else printf '%s' "$2"; fi
}
failed_row() {  # label what log
  FAILED+=("$1: $2 (log: ${3#"$WORK"/})")
  printf '    FAILED: %s; see %s\n' "$2" "$3" >&2
  tail -n 5 "$3" | sed 's/^/    | /' >&2 || true
  ROWS+=("| $1 | FAILED: $2 | | | | | | | | | | | | |")
}

# Runs odometry twice (the first with the cv_rgbd reference beside it) and both evaluations on SEQ,
# appends one table row. STATIC=1: a scene without moving objects, also scored by moving_share (on a
# view of SEQ without labels/ when it has them).
# run_row LABEL SEQ_DIR STATIC [extra dynvo_odometry args...]
run_row() {
  local label="$1" seq="$2" static="$3"; shift 3
  local run="$WORK/runs/$label" t0=$SECONDS
  mkdir -p "$run"
  say "$label: dynvo_odometry -labels_dir -bench_reference cv_rgbd, then -no_segmentation"
  if ! "$ODOM" -tum_dir "$seq" -out "$run/trajectory.txt" -labels_dir "$run/labels" \
       -bench_reference cv_rgbd -threads 1 -seed "$SEED" "$@" >"$run/odometry.out" \
       2>"$run/odometry.err"; then
    failed_row "$label" "dynvo_odometry" "$run/odometry.err"; return 0
  fi
  if ! "$ODOM" -tum_dir "$seq" -out "$run/trajectory_no_segmentation.txt" -no_segmentation \
       -threads 1 -seed "$SEED" "$@" >"$run/odometry_no_segmentation.out" \
       2>"$run/odometry_no_segmentation.err"; then
    failed_row "$label" "dynvo_odometry -no_segmentation" "$run/odometry_no_segmentation.err"; return 0
  fi
  local e
  for e in evaluate evaluate_no_segmentation; do
    local traj="$run/trajectory.txt"
    [ "$e" = evaluate ] || traj="$run/trajectory_no_segmentation.txt"
    if ! "$EVAL" "$seq/groundtruth.txt" "$traj" >"$run/$e.out" 2>&1; then
      failed_row "$label" "dynvo_evaluate $seq/groundtruth.txt $traj" "$run/$e.out"; return 0
    fi
  done
  if ! "$EVAL" -labels "$run/labels" -truth "$seq" >"$run/evaluate_labels.out" 2>&1; then
    failed_row "$label" "dynvo_evaluate -labels $run/labels -truth $seq" "$run/evaluate_labels.out"; return 0
  fi
  local share=""
  if [ "$static" = 1 ] && [ -d "$seq/labels" ]; then
    local view="$run/truth_without_labels" f
    mkdir -p "$view"
    for f in rgb depth rgb.txt depth.txt groundtruth.txt; do
      [ ! -e "$seq/$f" ] || ln -sfn "$seq/$f" "$view/$f"
    done
    if ! "$EVAL" -labels "$run/labels" -truth "$view" >"$run/evaluate_moving_share.out" 2>&1; then
      failed_row "$label" "dynvo_evaluate -labels $run/labels -truth $view" "$run/evaluate_moving_share.out"
      return 0
    fi
    share="$(grep '^moving_share=' "$run/evaluate_moving_share.out" | tail -n 1)" || true
  fi

  local odo ev evn seg ref refev
  odo="$(grep '^frames=' "$run/odometry.out" | tail -n 1)" || true
  ref="$(grep '^reference=' "$run/odometry.out" | tail -n 1)" || true
  refev="$(grep '^reference_rpe_trans_rmse=' "$run/odometry.out" | tail -n 1)" || true
  ev="$(grep '^rpe_trans_rmse=' "$run/evaluate.out" | tail -n 1)" || true
  evn="$(grep '^rpe_trans_rmse=' "$run/evaluate_no_segmentation.out" | tail -n 1)" || true
  seg="$(grep -E '^(moving_iou|moving_share)=' "$run/evaluate_labels.out" | tail -n 1)" || true
  [ -n "$odo" ] || { failed_row "$label" "no 'frames= lost= median_ms=' line from dynvo_odometry" "$run/odometry.out"; return 0; }
  [ -n "$ev" ] && [ -n "$evn" ] || { failed_row "$label" "no rpe_trans_rmse= line from dynvo_evaluate" "$run/evaluate.out"; return 0; }
  [ -n "$seg" ] || { failed_row "$label" "no segmentation line from dynvo_evaluate -labels" "$run/evaluate_labels.out"; return 0; }
  [ -n "$ref" ] && [ -n "$refev" ] || { failed_row "$label" "no reference= or reference_rpe_trans_rmse= line from dynvo_odometry -bench_reference cv_rgbd" "$run/odometry.out"; return 0; }

  local frames lost
  frames="$(kv frames "$odo")"
  lost="$(kv lost "$odo")"
  ROWS+=("| $label | $(fmt 4 "$(kv rpe_trans_rmse "$ev")") | $(fmt 4 "$(kv ate_rmse "$ev")") | ${lost:-–}/${frames:-–} \
| $(fmt 3 "$(kv moving_iou "$seg")") | $(fmt 3 "$(kv static_precision "$seg")") \
| $(fmt 3 "$(kv static_recall "$seg")") | $(fmt 3 "$(kv labelled "$seg")") | $(fmt 3 "$(kv bg_ok "$seg")") \
| $(fmt 3 "$(kv id_switch_rate "$seg")") | $(fmt 3 "$(kv moving_share "$seg $share")") \
| $(fmt 4 "$(kv rpe_trans_rmse "$evn")") | $(fmt 4 "$(kv reference_rpe_trans_rmse "$refev")") \
| $(fmt 1 "$(kv median_ms "$odo")") |")
  printf '    %s\n    %s\n    %s\n' "$ev" "$seg" "$odo"
  printf '    cv_rgbd: %s\n    cv_rgbd: %s\n' "$refev" "$ref"
  [ -z "$share" ] || printf '    without labels/: %s\n' "$share"
  printf '    -no_segmentation: %s\n' "$evn"
  printf '    %s stderr lines from dynvo_odometry (%s), %d s\n' \
    "$(wc -l <"$run/odometry.err")" "${run#"$WORK"/}/odometry.err" $((SECONDS - t0))
}

say "Accuracy benchmark: $FRAMES frames, seed $SEED for every sequence and for dynvo_odometry," \
    "realistic depth noise (no -clean), work folder $WORK"

# --- 1. synthetic development set ---
for s in "${SCENARIOS[@]}"; do
  selected "$s" || continue
  seq="$WORK/synthetic/$s"
  say "$s: dynvo_synthesize -scenario $s -frames $FRAMES -seed $SEED -threads 2"
  if ! "$SYNTH" -scenario "$s" -frames "$FRAMES" -seed "$SEED" -threads 2 -out "$seq" \
       >"$WORK/runs/synthesize_$s.log" 2>&1; then
    failed_row "$s" "dynvo_synthesize -scenario $s" "$WORK/runs/synthesize_$s.log"; continue
  fi
  sed 's/^/    /' "$WORK/runs/synthesize_$s.log"
  run_row "$s" "$seq" $((1 - HAS_OBJECT[$s]))
done

# --- 2. composites into the real recordings of static scenes, 3. the real recordings as they are ---
HAS_COMPOSITE=0
if "$SYNTH" -h 2>&1 | grep -q -- '-composite'; then HAS_COMPOSITE=1; fi
REAL_FRAMES_USED=()  # "name frames" of every real recording used
for real in "${REALS[@]}"; do
  real_dir="$DATA/$real"
  read -r -a camera <<<"${CAMERA[$real]}"
  want_composites=()
  if [ "${STATIC_SCENE[$real]}" = 1 ]; then
    for s in "${SCENARIOS[@]}"; do
      if [ "${HAS_OBJECT[$s]}" = 1 ] && selected "$real+$s" "$s"; then want_composites+=("$s"); fi
    done
    for s in "${PLAIN_SCENARIOS[@]}"; do
      if [ "${HAS_OBJECT[$s]:-0}" = 1 ] && selected "$real+$s+plain_objects" "$s"; then
        want_composites+=("$s+plain_objects")
      fi
    done
  fi
  want_real=0
  if selected "$real"; then want_real=1; fi
  want_half=0
  if selected "$real@15Hz" "$real"; then want_half=1; fi
  [ ${#want_composites[@]} -gt 0 ] || [ "$want_real" = 1 ] || [ "$want_half" = 1 ] || continue
  if [ ! -f "$real_dir/rgb.txt" ] || [ ! -f "$real_dir/depth.txt" ] || [ ! -f "$real_dir/groundtruth.txt" ]; then
    skipped="the ${#want_composites[@]} composite row(s) into $real"
    [ ${#want_composites[@]} -gt 0 ] || skipped=""
    [ "$want_real" = 0 ] || skipped="${skipped:+$skipped and }the $real row"
    [ "$want_half" = 0 ] || skipped="${skipped:+$skipped and }the $real@15Hz row"
    say "Skipping $skipped"
    echo "    no shared data at $real_dir (rgb.txt, depth.txt, groundtruth.txt);" \
         "set DYNVO_SHARED_DATA_DIR to the folder that holds $real/"
    continue
  fi
  real_frames="$(grep -vc '^#' "$real_dir/rgb.txt")" || true
  rframes=$(( FRAMES < real_frames ? FRAMES : real_frames ))  # frames used of the real recording
  REAL_FRAMES_USED+=("$real $rframes")
  if [ ${#want_composites[@]} -gt 0 ] && [ "$HAS_COMPOSITE" = 0 ]; then
    say "Skipping the ${#want_composites[@]} composite row(s) into $real (${want_composites[*]}):" \
        "this dynvo_synthesize has no -composite yet (dynvo_synthesize -h does not list it)"
    want_composites=()
  fi
  for want in "${want_composites[@]}"; do
    s="${want%+plain_objects}"
    look=()
    [ "$s" = "$want" ] || look=(-plain_objects)
    label="$real+$want"
    seq="$WORK/composite/$real/$want"
    log="$WORK/runs/composite_${real}_$want.log"
    say "$label: dynvo_synthesize -composite $real_dir -scenario $s ${look[*]} -frames $rframes -seed $SEED ${camera[*]}"
    if ! "$SYNTH" -composite "$real_dir" -scenario "$s" "${look[@]}" -out "$seq" -frames "$rframes" \
         -seed "$SEED" "${camera[@]}" >"$log" 2>&1; then
      failed_row "$label" "dynvo_synthesize -composite $real_dir -scenario $s ${look[*]}" "$log"
      continue
    fi
    sed 's/^/    /' "$log"
    run_row "$label" "$seq" 0 "${camera[@]}"
  done
  if [ "$want_real" = 1 ]; then
    # No labels/: dynvo_evaluate -labels reports moving_share (near 0 on a static scene).
    run_row "$real" "$real_dir" "${STATIC_SCENE[$real]}" "${camera[@]}" -max_frames "$rframes"
  fi
  if [ "$want_half" = 1 ]; then
    # The same span at half the rate: a view of the recording whose rgb.txt keeps the 1st, 3rd,
    # ... of its first rframes colour frames (each still paired with its nearest depth image).
    view="$WORK/halfrate/$real"
    mkdir -p "$view"
    for f in rgb depth depth.txt groundtruth.txt; do ln -sfn "$real_dir/$f" "$view/$f"; done
    grep -v '^#' "$real_dir/rgb.txt" | head -n "$rframes" | awk 'NR % 2 == 1' >"$view/rgb.txt"
    run_row "$real@15Hz" "$view" "${STATIC_SCENE[$real]}" "${camera[@]}"
  fi
done

# --- table ---
TOTAL=$((SECONDS - T_START))
commit="$COMMIT"
if [ "$(git_state)" != "$COMMIT" ] || [ "$(bins_stamp)" != "$BINS_AT_START" ]; then
  [ "$(git_state)" = "$COMMIT" ] || commit="$commit (source changed during the run: now $(git_state))"
  [ "$(bins_stamp)" = "$BINS_AT_START" ] || commit="$commit (binaries rebuilt during the run)"
  say "Warning: the source or the binaries changed while the benchmark ran; rerun for a consistent table"
fi
{
  printf 'dynvo %s, %s: %d frames per synthetic sequence' "$commit" "$(date -u +%Y-%m-%d)" "$FRAMES"
  if [ ${#REAL_FRAMES_USED[@]} -gt 0 ]; then
    printf ' (frames used of the real recordings, also for their composites: %s)' \
      "$(commas "${REAL_FRAMES_USED[@]}")"
  fi
  printf ', seed %s,' "$SEED"
  printf ' realistic depth noise; RPE: translational RMSE over 1 s, ATE: RMSE after alignment;'
  printf ' lost: lost/total frames; RPE cv_rgbd: OpenCV'"'"'s RGB-D odometry frame to frame over the whole'
  printf ' image on the same frames (dynvo_odometry -bench_reference cv_rgbd);'
  printf ' median ms per frame with segmentation, 1 thread.\n\n'
  printf '| sequence | RPE m/s | ATE m | lost | moving_iou | static_precision | static_recall | labelled'
  printf ' | bg_ok | id_switch_rate | moving_share | RPE -no_segmentation | RPE cv_rgbd | median ms |\n'
  printf '|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n'
  [ ${#ROWS[@]} -eq 0 ] || printf '%s\n' "${ROWS[@]}"
} >"$WORK/table.md"
say "Table ($WORK/table.md)"
cat "$WORK/table.md"
say "Total time: $((TOTAL / 60)) min $((TOTAL % 60)) s for ${#ROWS[@]} row(s); logs in $WORK/runs/"
if [ ${#FAILED[@]} -gt 0 ]; then
  printf 'FAILED:\n' >&2
  printf '  %s\n' "${FAILED[@]}" >&2
  exit 1
fi
