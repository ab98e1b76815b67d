#!/usr/bin/env bash
# Fingerprints of the command-line program's outputs: runs the commands that need no DDS (sim, calibrate,
# allan, replay, score, convert) on fixed inputs (examples/ and small simulated logs) and prints one
# "sha256  name" line per output file, per standard output and per standard error, with each run's exit
# status in its stdout record. The UTC time of the run (provenance: created_utc) is masked, nothing else
# (HDF5 files: see below).
# Two builds whose lists are equal write the same bytes. Usage: bench/cli_outputs.sh [BUILD_DIR] [KEEP_DIR]
# (the tetra target built; KEEP_DIR keeps the files for a look).
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$src/build}" && pwd)
if [ -n "${2:-}" ]; then
  mkdir -p "$2"
  dir=$(cd "$2" && pwd)
else
  dir=$(mktemp -d)
  trap 'rm -rf "$dir"' EXIT
fi
cd "$dir"
rm -rf ./*
cp "$src/examples/turntable.csv" "$src/examples/factory.yaml" "$src/examples/fusion.yaml" \
  "$src/examples/sim/slews_custom.yaml" "$src/examples/sim/closed_loop_nadir.yaml" .
export PATH="$build:$PATH"
export LC_ALL=C

n=0
# run NAME ARGS...: tetra ARGS with stdout and stderr kept, the exit status appended to stdout's record.
run() {
  local name=$1
  shift
  n=$((n + 1))
  local status=0
  tetra "$@" >"out_${name}.stdout" 2>"out_${name}.stderr" || status=$?
  echo "exit=$status" >>"out_${name}.stdout"
}

# --- sim -------------------------------------------------------------------------------------------
run sim_unit sim --write-unit unit.yaml
run sim_turntable sim turntable --seed 1 --rate-hz 2 -o tt.csv
run sim_static sim static --seed 2 --minutes 3 --rate-hz 20 -o static.csv
run sim_orbit sim orbit --seed 3 --minutes 6 --rate-hz 10 --acs-amplitude 0.04 --acs-accel 1e-4 \
  --fault gyro=3,kind=stuck,at=120 --truth truth.csv -o orbit.csv
run sim_laborbit sim lab-orbit --seed 4 --minutes 2 --rate-hz 5 --jitter 0.001 --drop 0.01 -o lab.csv
run sim_slews sim slews_custom.yaml --seed 5 --minutes 3 --rate-hz 5 --add-fault gyro=1,kind=bias,at=30,size=0.01 \
  -o slews.csv --truth slews_truth.csv
run sim_bad sim nowhere.yaml -o never.csv
run sim_bad_fault sim orbit --fault gyro=9,kind=stuck,at=1 -o never.csv
run sim_tt_minutes sim turntable --minutes 3 -o never.csv
run sim_tt_plan sim turntable --wrap --order 1,2,5,6 --table-rate 3 --revolutions 2 --range 400 --latitude 10
run sim_refs sim orbit --seed 6 --minutes 0.5 --reference-bias 5,10,20 --reference-misid 1,20,5 \
  --reference-latency 0.2 --reference-noise 3 --orbit-period 95 -o refs.csv
run sim_wrap_static sim static --wrap -o never.csv
run sim_tt_refbias sim turntable --reference-bias 1,2,3
run sim_tt_fault sim turntable --fault gyro=1,kind=stuck,at=1 -o never.csv
run sim_table_rate sim orbit --table-rate 3 -o never.csv
run sim_too_long sim static --minutes 100000 --rate-hz 1000 -o never.csv
run sim_no_out sim static --minutes 1
run sim_loop_out sim orbit --closed-loop --minutes 1 -o never.csv
run sim_closed_loop sim closed_loop_nadir.yaml --closed-loop --seed 5 --pointing loop.csv --summary loop.json
run sim_unit_scenario sim orbit --write-unit never.yaml
run sim_no_scenario sim
run sim_same_file sim static --minutes 1 -o same.csv --truth same.csv

# --- calibrate -------------------------------------------------------------------------------------
run cal_sixteen calibrate turntable.csv -o cal.yaml
run cal_batch calibrate turntable.csv --method batch --compare factory.yaml -o cal_batch.yaml
run cal_seed calibrate turntable.csv --bias-model seed --latitude -23 --unit u9 -o -
run cal_tt calibrate tt.csv -o cal_tt.yaml
run cal_bad calibrate missing.csv -o x.yaml
run cal_bad_combo calibrate turntable.csv --method batch --bias-model seed -o x.yaml
run cal_compare_missing calibrate turntable.csv --compare missing.yaml -o x.yaml
run cal_same calibrate turntable.csv -o turntable.csv
run cal_no_noise calibrate turntable.csv --noise factory.yaml -o x.yaml

# --- allan -----------------------------------------------------------------------------------------
cp cal_tt.yaml cal_noise.yaml
run allan_all allan static.csv --calibration cal_tt.yaml --csv allan.csv --json allan.json \
  --plot allan.png --kalibr kalibr.yaml
run allan_update allan static.csv --calibration cal_noise.yaml --update-calibration --taus octave
run allan_gyro allan static.csv --gyro 2 --gyro 4 --taus 0.1,1,10 --confidence 0.9 --csv allan_g.csv
run allan_bad allan static.csv --taus nonsense
run allan_bad_gyro allan static.csv --gyro 7
run allan_no_cal allan static.csv --update-calibration
run allan_kalibr_no_cal allan static.csv --kalibr never.yaml
run allan_dt allan static.csv --dt-tolerance 0.7
run allan_confidence allan static.csv --confidence 1.5
run allan_same allan static.csv --csv static.csv
run cal_noise calibrate turntable.csv --noise cal_noise.yaml -o cal_with_noise.yaml

# --- replay ----------------------------------------------------------------------------------------
printf '{"time_s": 200.0, "command": "exclude", "gyro": 2}\n{"time_s": 260.0, "command": "reinstate", "gyro": 2}\n' \
  >commands.jsonl
run replay_orbit replay orbit.csv --calibration unit.yaml --attitude att.csv --events ev.jsonl
run replay_cfg replay orbit.csv --calibration unit.yaml --config fusion.yaml --verbose \
  --attitude att_cfg.csv --events ev_cfg.jsonl
run replay_cmd replay orbit.csv --calibration unit.yaml --commands commands.jsonl --attitude att_cmd.csv \
  --events ev_cmd.jsonl
run replay_slews replay slews.csv --calibration unit.yaml --attitude att_slews.csv --events ev_slews.jsonl
run replay_bad replay orbit.csv --calibration missing.yaml --attitude x.csv --events x.jsonl
run replay_q replay orbit.csv --calibration unit.yaml --initial-q 1,0,0 --attitude x.csv --events x.jsonl
run replay_q_norm replay orbit.csv --calibration unit.yaml --initial-q 1,1,0,0 --attitude x.csv --events x.jsonl
run replay_q_ok replay orbit.csv --calibration unit.yaml --initial-q 1,0,0,0 --latitude 45 \
  --attitude att_q.csv --events ev_q.jsonl
run replay_same replay orbit.csv --calibration unit.yaml --attitude orbit.csv --events x.jsonl

# --- score -----------------------------------------------------------------------------------------
run score_orbit score att.csv truth.csv --json score.json --plot score.png
run score_slews score att_slews.csv slews_truth.csv --axis 0,1,1 --time-tolerance 1e-3
run score_bad_axis score att.csv truth.csv --axis body
run score_bad score att.csv missing.csv
run score_zero_axis score att.csv truth.csv --axis 0,0,0
run score_tolerance score att.csv truth.csv --time-tolerance -1

# --- convert ---------------------------------------------------------------------------------------
run convert_h5 convert orbit.csv orbit.h5
run convert_h5z convert static.csv static.h5 --compress
run convert_back convert orbit.h5 orbit_back.csv
run convert_backz convert static.h5 static_back.csv
run convert_bad convert missing.csv x.h5
run convert_same convert orbit.csv orbit.csv

# Fingerprints: every file the runs left (inputs copied in included), the run time masked (and the closed
# loop's wall time, "run 0.12 s", on its standard output). HDF5 files
# carry their objects' modification times in binary: they are fingerprinted by their size and by the CSV
# converted back from them (convert_back*).
for f in $(ls | sort); do
  case $f in
  *.h5)
    echo "size=$(stat -c %s "$f")  $f"
    continue
    ;;
  esac
  perl -0777 -pe 's/(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z)/"X" x length($1)/ge; s/; run \d+\.\d+ s$/; run X s/mg' "$f" |
    sha256sum |
    sed "s|-\$|$f|"
done
echo "# $n runs" >&2
