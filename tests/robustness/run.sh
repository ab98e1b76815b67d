#!/usr/bin/env bash
# Robustness suite (docs/reliability.md, "Hostile inputs"): every command against a table of hostile
# inputs, options and output paths. Each case checks the exit status, that a failure prints exactly
# one line on stderr naming what it must name, no crash (no signal, no "internal error"), bounded time
# (TIME_LIMIT_S) and memory (MEMORY_LIMIT_KB of address space), and that every file present before the
# run (inputs, pre-existing outputs) is byte-identical afterwards unless the case expects it written.
# Usage: run.sh TETRA WORK_DIR
set -uo pipefail
TETRA=$(realpath "$1")
WORK=$2
TIME_LIMIT_S=20
MEMORY_LIMIT_KB=$((4 * 1024 * 1024))
# AddressSanitizer reserves terabytes of address space: under it (scripts/sanitize.sh) the limit is
# left to ASan's own allocator checks.
if ldd "$TETRA" 2>/dev/null | grep -q libasan; then MEMORY_LIMIT_KB=unlimited; fi
rm -rf "$WORK"
mkdir -p "$WORK"
cd "$WORK" || exit 1

pass=0
fail=0
declare -A class_count
failures=()

# snapshot DIR: "path sha256 type" of every entry, symbolic links and FIFOs by kind.
snapshot() {
  find . -mindepth 1 -not -path './_*' -printf '%p %y %l\n' | sort | while read -r p y l; do
    if [[ $y == f ]]; then echo "$p f $(sha256sum <"$p" | cut -c1-64)"; else echo "$p $y $l"; fi
  done
}

# check CLASS NAME EXPECTED_STATUS STDERR_PATTERN CHANGED_FILES -- ARGS...
# CHANGED_FILES: space-separated paths the case may create or change ("" for none).
check() {
  local class=$1 name=$2 want=$3 pattern=$4 changed=$5
  shift 6
  local before after status start elapsed
  before=$(snapshot)
  start=$(date +%s%N)
  (ulimit -v "$MEMORY_LIMIT_KB"; exec timeout -s KILL "$TIME_LIMIT_S" "$TETRA" "$@") \
    >_stdout 2>_stderr </dev/null
  status=$?
  elapsed=$((($(date +%s%N) - start) / 1000000))
  after=$(snapshot)
  local why=""
  [[ $status == "$want" ]] || why+="exit $status (want $want); "
  ((status >= 124)) && why+="killed or crashed (limit ${TIME_LIMIT_S}s / ${MEMORY_LIMIT_KB} kB); "
  grep -q "internal error" _stderr && why+="internal error; "
  if [[ $want != 0 ]]; then
    local lines
    lines=$(wc -l <_stderr)
    [[ $lines == 1 ]] || why+="$lines stderr lines; "
    grep -qE -- "$pattern" _stderr || why+="stderr lacks /$pattern/; "
  fi
  local diff_lines
  diff_lines=$(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | cut -c3- | cut -d' ' -f1 | sort -u)
  for p in $diff_lines; do
    [[ " $changed " == *" ${p#./} "* ]] || why+="changed $p; "
  done
  class_count[$class]=$((${class_count[$class]:-0} + 1))
  if [[ -z $why ]]; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    failures+=("[$class] $name: $why stderr: $(head -c 300 _stderr | tr '\n' '|')")
  fi
  printf '%-13s %-58s %s (%d ms)\n' "$class" "$name" "$([[ -z $why ]] && echo ok || echo FAIL)" "$elapsed"
}

# A case run through a shell (pipes, process checks): check_sh CLASS NAME -- SCRIPT (exit 0 = pass).
check_sh() {
  local class=$1 name=$2 script=$3
  class_count[$class]=$((${class_count[$class]:-0} + 1))
  if (ulimit -v "$MEMORY_LIMIT_KB"; timeout -s KILL "$TIME_LIMIT_S" bash -c "$script") >_sh_out 2>&1; then
    pass=$((pass + 1))
    printf '%-13s %-58s ok\n' "$class" "$name"
  else
    fail=$((fail + 1))
    failures+=("[$class] $name: $(tail -c 300 _sh_out | tr '\n' '|')")
    printf '%-13s %-58s FAIL\n' "$class" "$name"
  fi
}

# --- fixtures ---------------------------------------------------------------------------------------
mkdir -p _fix
"$TETRA" sim turntable -o tt.csv --seed 3 2>/dev/null || { echo "fixture: sim turntable failed"; exit 1; }
"$TETRA" calibrate tt.csv -o cal.yaml >/dev/null 2>&1 || { echo "fixture: calibrate failed"; exit 1; }
"$TETRA" sim static --minutes 0.5 --rate-hz 20 -o log.csv 2>/dev/null || { echo "fixture: sim static failed"; exit 1; }
printf 'pipeline:\n  onset_sigma: 6\n' >cfg.yaml
echo "old attitude" >att.csv
echo "old events" >ev.jsonl
echo "old output" >out.csv
TT=tt.csv CAL=cal.yaml LOG=log.csv

# A calibration with one line replaced (sed expression) as FILE.
cal_with() { sed "$1" "$CAL" >"$2"; }

# --- outputs: never lose data -----------------------------------------------------------------------
check outputs "calibrate -o = its input" 2 "--output tt.csv.*same file as the input" "" -- \
  calibrate "$TT" -o "$TT"
check outputs "replay --attitude = the log" 2 "--attitude log.csv.*same file as the input" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude "$LOG" --events ev.jsonl
check outputs "replay --events = the calibration" 2 "--events cal.yaml.*same file as the input" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude att.csv --events "$CAL"
check outputs "replay --attitude = --events" 2 "--events att.csv.*same file as the output --attitude" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude att.csv --events att.csv
check outputs "allan --csv = --json" 2 "--json out.csv.*same file as the output --csv" "" -- \
  allan "$LOG" --csv out.csv --json out.csv
check outputs "allan --json = the log" 2 "--json log.csv.*same file as the input" "" -- allan "$LOG" --json "$LOG"
check outputs "sim --truth = --out" 2 "--truth out.csv.*same file as the output --out" "" -- \
  sim static --minutes 0.1 -o out.csv --truth out.csv
check outputs "sim --out = its --unit" 2 "--out cal.yaml.*same file as the input --unit" "" -- \
  sim static --minutes 0.1 --unit "$CAL" -o "$CAL"
ln -s "$TT" tt_link.csv
check outputs "calibrate -o = a symlink to its input" 2 "same file as the input" "" -- \
  calibrate "$TT" -o tt_link.csv
ln "$LOG" log_hard.csv
check outputs "replay --attitude = a hard link to the log" 2 "same file as the input" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude log_hard.csv --events ev.jsonl
check outputs "replay --attitude ./att.csv = --events att.csv" 2 "same file as the output" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude ./att.csv --events att.csv
check outputs "failed run (not a gyro log) keeps both outputs" 2 "tt.csv:[0-9]+: header" "" -- \
  replay "$TT" --calibration "$CAL" --attitude att.csv --events ev.jsonl
check outputs "second output refused: first kept" 2 "--events nodir/ev.jsonl" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude att.csv --events nodir/ev.jsonl
check outputs "output is a folder" 2 "--output _fix.*folder" "" -- calibrate "$TT" -o _fix
check outputs "output folder missing" 2 "--output nodir/c.yaml" "" -- calibrate "$TT" -o nodir/c.yaml
echo "keep me" >att2.csv.tmp
check outputs "a file named like a temporary file survives" 0 "" "att2.csv ev2.jsonl" -- \
  replay "$LOG" --calibration "$CAL" --attitude att2.csv --events ev2.jsonl
check outputs "replay succeeds: both outputs replaced" 0 "" "att.csv ev.jsonl" -- \
  replay "$LOG" --calibration "$CAL" --attitude att.csv --events ev.jsonl
check outputs "--attitude /dev/null stays a device" 0 "" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude /dev/null --events /dev/null
check_sh outputs "/dev/null is still a character device" "test -c /dev/null"
cp "$CAL" real_cal.yaml
ln -s real_cal.yaml cal_link.yaml
check outputs "calibrate -o symlink: written through" 0 "" "real_cal.yaml" -- calibrate "$TT" -o cal_link.yaml
check_sh outputs "the symlink is still a symlink" "test -L cal_link.yaml && grep -q gyros: real_cal.yaml"
check_sh outputs "-o - writes standard output" \
  "'$TETRA' calibrate $TT -o - 2>/dev/null | grep -q 'scale_factor_V_per_dps:' && test ! -e ./-"
check_sh outputs "output to a FIFO is written through" \
  "mkfifo fifo1 && (cat fifo1 >_fifo_copy &) && '$TETRA' sim static --minutes 0.1 -o fifo1 2>/dev/null && sleep 0.2 && test -p fifo1 && grep -q time_s,g1 _fifo_copy; rc=\$?; rm -f fifo1 _fifo_copy; exit \$rc"
check_sh outputs "closed stdout (SIGPIPE): the file is still written" \
  "rm -f pipe_cal.yaml; '$TETRA' calibrate $TT -o pipe_cal.yaml 2>/dev/null | head -c 1 >/dev/null; grep -q gyros: pipe_cal.yaml; rc=\$?; rm -f pipe_cal.yaml; exit \$rc"
check_sh outputs "a failed run leaves no temporary file" "! ls -A | grep -q '\.tetra-'"

# --- inputs: bounded, clear ---------------------------------------------------------------------
check inputs "input is a folder" 2 "_fix: is a folder" "" -- replay _fix --calibration "$CAL" --attitude a.csv --events e.jsonl
check inputs "input is /dev/zero" 2 "/dev/zero: is a character device" "" -- allan /dev/zero
check inputs "calibration is /dev/zero" 2 "/dev/zero" "" -- replay "$LOG" --calibration /dev/zero --attitude a.csv --events e.jsonl
check inputs "missing input" 2 "nofile.csv: cannot open" "" -- calibrate nofile.csv -o c.yaml
: >empty.csv
check inputs "empty CSV" 2 "empty.csv" "" -- allan empty.csv
awk 'BEGIN { printf "time_s"; for (i = 1; i <= 200000; ++i) printf ",g%d", i; printf "\n" }' >wide.csv
check inputs "200,000-column header" 2 "wide.csv:1: header: 200001 columns" "" -- allan wide.csv
awk 'BEGIN { printf "time_s"; for (i = 1; i <= 1000; ++i) printf ",c%d", i; printf "\n"; for (i = 0; i < 3000000; ++i) print "" }' >blank.csv
check inputs "wide header + 3 million blank lines" 2 "blank.csv" "" -- allan blank.csv
head -c 200000 /dev/urandom >garbage.csv
check inputs "binary garbage" 2 "garbage.csv" "" -- allan garbage.csv
printf 'time_s,g1,g2,g3,g4\n0,1,2,3,\x004\n' >nul.csv
check inputs "NUL byte in a cell" 2 "nul.csv:2" "" -- allan nul.csv
awk 'BEGIN { printf "time_s,g1\n0,"; for (i = 0; i < 2000000; ++i) printf "1"; printf "\n" }' >longcell.csv
check inputs "a 2 MB cell" 2 "longcell.csv:2: column 'g1'" "" -- allan longcell.csv
printf 'a: &a [x, x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\nc: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]\ne: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\ng: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f, *f]\nh: [*g, *g, *g, *g, *g, *g, *g, *g, *g, *g]\n' >bomb.yaml
check inputs "YAML alias bomb" 2 "bomb.yaml" "" -- replay "$LOG" --calibration bomb.yaml --attitude a.csv --events e.jsonl
awk 'BEGIN { for (i = 0; i < 20000; ++i) printf "["; print "" }' >deep.yaml
check inputs "YAML nested 20,000 deep" 2 "deep.yaml" "" -- replay "$LOG" --calibration deep.yaml --attitude a.csv --events e.jsonl
sed 's/$/\r/' "$LOG" >crlf.csv
check inputs "CRLF line ends are read" 0 "" "" -- allan crlf.csv --taus 1,2

# --- files: strict rules -----------------------------------------------------------------------------
cal_with 's/^unit:.*/unit: a\nunit: b/' dupkey.yaml
check yaml "duplicate key" 2 "dupkey.yaml:[0-9]+: key 'unit' appears twice" "" -- \
  replay "$LOG" --calibration dupkey.yaml --attitude a.csv --events e.jsonl
{ cat "$CAL"; printf -- '---\nunit: other\n'; } >twodoc.yaml
check yaml "a second YAML document" 2 "twodoc.yaml:[0-9]+: a second YAML document" "" -- \
  replay "$LOG" --calibration twodoc.yaml --attitude a.csv --events e.jsonl
printf 'pipelin:\n  onset_sigma: 6\n' >typo.yaml
check yaml "top-level typo in a pipeline configuration" 2 "typo.yaml:1: unknown key 'pipelin'" "" -- \
  replay "$LOG" --calibration "$CAL" --config typo.yaml --attitude a.csv --events e.jsonl
cal_with 's/^latitude_deg:.*/latitude_deg: 95/' lat95.yaml
grep -q '^latitude_deg' lat95.yaml || sed -i '1a latitude_deg: 95' lat95.yaml
check yaml "latitude 95 in a calibration" 2 "lat95.yaml:[0-9]+: latitude_deg: must be within" "" -- \
  replay "$LOG" --calibration lat95.yaml --attitude a.csv --events e.jsonl
cal_with '0,/bias_V: /s/\( *\)bias_V: .*/\1bias_V: -1e-6/; t; ' negsig.yaml
awk 'BEGIN{n=0} /sigma:/ {s=1} s && /bias_V:/ && !done {sub(/bias_V: .*/, "bias_V: -1e-6"); done=1} {print}' "$CAL" >negsig.yaml
check yaml "negative sigma" 2 "negsig.yaml:[0-9]+: gyros\[0\].sigma.bias_V: a 1-sigma must not be negative" "" -- \
  replay "$LOG" --calibration negsig.yaml --attitude a.csv --events e.jsonl
cal_with '0,/bias_V:/s/bias_V: .*/bias_V: 0x10/' hexcal.yaml
check yaml "hexadecimal number in YAML" 2 "hexcal.yaml:[0-9]+: gyros\[0\].bias_V: '0x10' is not a number" "" -- \
  replay "$LOG" --calibration hexcal.yaml --attitude a.csv --events e.jsonl
cal_with 's/^unit:.*/unit: [a, b]/' typeunit.yaml
check yaml "type error names the key" 2 "typeunit.yaml:[0-9]+: unit: expected a text value" "" -- \
  replay "$LOG" --calibration typeunit.yaml --attitude a.csv --events e.jsonl
printf 'pipeline:\n  stuck_repeat_count: abc\n' >badint.yaml
check yaml "bad integer names the key" 2 "badint.yaml:2: pipeline.stuck_repeat_count" "" -- \
  replay "$LOG" --calibration "$CAL" --config badint.yaml --attitude a.csv --events e.jsonl
# The first data row (the line after the header) with its g1 cell replaced.
first_row=$(grep -n '^time_s' "$LOG" | cut -d: -f1)
first_row=$((first_row + 1))
awk -F, -v OFS=, -v r=$first_row 'NR == r { $2 = "0x1p3" } { print }' "$LOG" >hexcell.csv
check csv "hexadecimal number in a CSV cell" 2 "hexcell.csv:$first_row: column 'g1': '0x1p3' is not a number" "" -- allan hexcell.csv
awk -F, -v OFS=, -v r=$first_row 'NR == r { sub(/\./, ";", $2) } { print }' "$LOG" >semicell.csv
check csv "semicolon inside a cell" 2 "semicell.csv:$first_row: column 'g1'" "" -- allan semicell.csv
awk -F, -v OFS=, -v r=$first_row 'NR == r { $2 = "1" } NR == r { $0 = $0 ",5" } { print }' "$LOG" >commacell.csv
check csv "decimal comma splits the row" 2 "commacell.csv:$first_row: expected 5 fields" "" -- allan commacell.csv
awk -F, -v OFS=, -v r=$first_row 'NR == r { $2 = "nan(0x1)" } { print }' "$LOG" >nanpay.csv
check csv "nan with a payload" 2 "nanpay.csv:$first_row: column 'g1'" "" -- allan nanpay.csv
sed 's/^# seed=.*/# latitude_deg=0x10/' "$TT" >hexmeta.csv
grep -q 'latitude_deg=0x10' hexmeta.csv || sed -i '1i # latitude_deg=0x10' hexmeta.csv
sed -i '/^# latitude_deg=-/d' hexmeta.csv
check csv "hexadecimal latitude comment" 2 "hexmeta.csv: comment '# latitude_deg=0x10'" "" -- calibrate hexmeta.csv -o c.yaml

# --- command line ------------------------------------------------------------------------------------
check options "help UNKNOWN" 2 "unknown command 'nosuch'" "" -- help nosuch
check options "unknown command" 2 "unknown command 'nosuch'" "" -- nosuch
check options "--version" 0 "" "" -- --version
check options "option given twice" 2 "--latitude" "" -- calibrate "$TT" -o c.yaml --latitude 1 --latitude 2
check options "empty --latitude" 2 "--latitude" "" -- calibrate "$TT" -o c.yaml --latitude ""
check options "hexadecimal --latitude" 2 "--latitude" "" -- calibrate "$TT" -o c.yaml --latitude 0x10
check options "decimal comma --latitude" 2 "--latitude" "" -- calibrate "$TT" -o c.yaml --latitude 1,5
check options "--latitude 95" 2 "--latitude" "" -- replay "$LOG" --calibration "$CAL" --latitude 95 --attitude a.csv --events e.jsonl
check options "--latitude nan" 2 "--latitude" "" -- replay "$LOG" --calibration "$CAL" --latitude nan --attitude a.csv --events e.jsonl
check options "negative --seed" 2 "--seed" "" -- sim static --minutes 0.1 --seed -1 -o s.csv
check options "overflowing --seed" 2 "--seed" "" -- sim static --minutes 0.1 --seed 99999999999999999999999 -o s.csv
check options "fault field given twice" 2 "at: given twice" "" -- sim static --minutes 0.1 --fault gyro=1,kind=stuck,at=1,at=2 -o s.csv
check options "fault after the run ends" 2 "after the end of the run" "" -- sim static --minutes 0.1 --fault gyro=1,kind=stuck,at=600 -o s.csv
check options "--initial-q hexadecimal" 2 "--initial-q" "" -- replay "$LOG" --calibration "$CAL" --initial-q 0x1,0,0,0 --attitude a.csv --events e.jsonl
check options "--dt-tolerance out of range" 2 "--dt-tolerance" "" -- allan "$LOG" --dt-tolerance 3
check options "--gyro hexadecimal" 2 "--gyro" "" -- allan "$LOG" --gyro 0x1

# --- round trips -------------------------------------------------------------------------------------
weird=$'odd "name" \\ with\nnewline, comma #hash'
check roundtrip "calibrate --unit with quote, backslash, newline" 0 "" "weird.yaml" -- calibrate "$TT" -o weird.yaml --unit "$weird"
check roundtrip "that calibration reads back" 0 "" "wa.csv we.jsonl" -- replay "$LOG" --calibration weird.yaml --attitude wa.csv --events we.jsonl
check roundtrip "sim with that unit" 0 "" "wlog.csv" -- sim static --minutes 0.1 --unit weird.yaml -o wlog.csv
check roundtrip "its log reads back" 0 "" "" -- allan wlog.csv --taus 1
check_sh roundtrip "the unit name survives both" \
  "grep -q '^unit: \"odd' weird.yaml && grep -q '^# unit=odd' wlog.csv"
awk 'BEGIN {
  print "unit: ten"; print "gyros:"
  for (i = 1; i <= 10; ++i) {
    a = 0.6 * i; x = cos(a) * 0.6; y = sin(a) * 0.6; z = (i % 2 ? 0.8 : -0.8)
    printf "  - id: %d\n    scale_factor_V_per_dps: 0.08\n    bias_V: 0\n    axis: [%.17g, %.17g, %.17g]\n", i, x, y, z
    print "    noise:\n      arw_dps_rtHz: 3e-5"
  } }' >ten.yaml
check roundtrip "sim with 10 gyros" 0 "" "ten.csv" -- sim static --minutes 0.1 --unit ten.yaml -o ten.csv
check roundtrip "replay with 10 gyros" 0 "" "ten_att.csv ten_ev.jsonl" -- \
  replay ten.csv --calibration ten.yaml --attitude ten_att.csv --events ten_ev.jsonl
# 11 columns, then sigma_x/y/z_deg, bias_1..10_dps and pl_x/y/z_deg: 27 fields a row.
check_sh roundtrip "attitude CSV: one gyros field for N = 10" \
  "grep -v '^#' ten_att.csv | awk -F, 'NF != 27 { bad = 1 } END { exit bad }' && grep -q ',1;2;3;4;5;6;7;8;9;10,' ten_att.csv"
cp "$LOG" $'bad\xffname.csv'
check roundtrip "invalid UTF-8 file name into JSON" 0 "" "n.json" -- allan $'bad\xffname.csv' --taus 1 --json n.json
check_sh roundtrip "the JSON is valid UTF-8" "iconv -f UTF-8 -t UTF-8 n.json >/dev/null"
check_sh provenance "provenance in CSV, YAML, JSON outputs" \
  "grep -q '^# tetra_version=' att.csv && grep -q '^# created_utc=' att.csv && grep -q '# tetra_version=' weird.yaml && grep -q '\"provenance\"' n.json"

# --- summary -----------------------------------------------------------------------------------------
echo
for c in "${!class_count[@]}"; do printf '%s %d\n' "$c" "${class_count[$c]}"; done | sort
echo "robustness: $pass passed, $fail failed, $((pass + fail)) cases"
for f in "${failures[@]}"; do echo "FAIL $f"; done
((fail == 0))
