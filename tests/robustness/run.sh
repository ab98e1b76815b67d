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
SRC=$(cd "$(dirname "$0")/../.." && pwd)
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
# FIFOs, sockets and devices other than /dev/null are refused before anything is opened (opening a FIFO
# blocks until a reader comes; pipe standard output instead): CSV and HDF5 outputs, record, campaign.
mkfifo fifo1 fifo1.h5
check outputs "sim -o a FIFO: refused" 2 "--out fifo1: is a FIFO: an output must be a regular file" "" -- \
  sim static --minutes 0.1 -o fifo1
check outputs "sim -o a FIFO .h5: refused" 2 "--out fifo1.h5: is a FIFO" "" -- sim static --minutes 0.1 -o fifo1.h5
check outputs "convert into a FIFO .h5: refused" 2 "fifo1.h5: is a FIFO" "" -- convert "$LOG" fifo1.h5
check outputs "replay --attitude a FIFO: refused" 2 "--attitude fifo1: is a FIFO" "" -- \
  replay "$LOG" --calibration "$CAL" --attitude fifo1 --events ev.jsonl
check outputs "record --out a FIFO: refused before DDS" 2 "--out fifo1.h5: is a FIFO" "" -- \
  record --out fifo1.h5 --duration 1
check outputs "sim -o /dev/full: refused (a device)" 2 "--out /dev/full: is a character device" "" -- \
  sim static --minutes 0.1 -o /dev/full
mkdir -p camp_fifo && mkfifo camp_fifo/runs.csv
check outputs "campaign whose runs.csv is a FIFO: refused" 2 "runs.csv: is a FIFO" "" -- \
  campaign "$SRC/examples/campaign.yaml" --out camp_fifo
# Every file a campaign writes in --out is checked first (run and merge): in a folder of no campaign any of
# them is another program's (report.md was replaced); a symbolic link out of the folder is refused.
mkdir -p camp_foreign && echo "someone's notes" >camp_foreign/report.md
check outputs "campaign --out a folder of no campaign holding report.md" 2 \
  "camp_foreign/report.md: the output folder holds files of no campaign" "" -- \
  campaign "$SRC/examples/campaign.yaml" --out camp_foreign
mkdir -p camp_link && ln -s ../out.csv camp_link/runs.csv
check outputs "campaign --out whose runs.csv links out of it" 2 \
  "camp_link/runs.csv: a symbolic link out of the output folder" "" -- \
  campaign "$SRC/examples/campaign.yaml" --out camp_link
printf 'loop: open\nscenarios: [orbit]\nduration_s: 30\nkinds: [stuck]\ngyros: [1]\nonsets_s: [10]\nseeds: [1]\n' >tiny_camp.yaml
"$TETRA" campaign tiny_camp.yaml --out camp_s1 --no-report 2>/dev/null || { echo "fixture: campaign failed"; exit 1; }
check outputs "campaign merge into a folder of no campaign holding report.md" 2 \
  "camp_foreign/report.md: the output folder holds files of no campaign" "" -- \
  campaign merge camp_foreign camp_s1
# A file without write permission is never replaced (the rename would go around the protection).
echo "protected" >ro.csv && chmod 0444 ro.csv
check outputs "sim -o a 0444 file: refused" 2 "--out ro.csv: is write-protected" "" -- sim static --minutes 0.1 -o ro.csv
check_sh outputs "as nobody: a 0444 file of its own is never replaced" \
  "d=\$(mktemp -d) && chmod 0777 \$d && echo keep >\$d/keep.csv && chmod 0444 \$d/keep.csv && chown nobody \$d/keep.csv &&
   ! setpriv --reuid=nobody --regid=nogroup --clear-groups '$TETRA' sim static --minutes 0.1 -o \$d/keep.csv 2>\$d/err &&
   grep -q 'is write-protected' \$d/err && test \"\$(cat \$d/keep.csv)\" = keep && ! ls -A \$d | grep -q tetra-; rc=\$?; rm -rf \$d; exit \$rc"
# SIGTERM or SIGINT mid-run: the temporary output goes, the previous file stays, the signal ends the run.
# (set -m: a background job keeps SIGINT; the run is signalled once its temporary file exists.)
for sig in TERM INT; do
  check_sh outputs "SIG$sig during sim: no temporary file, previous output kept" \
    "set -m; echo previous >sig_$sig.h5; '$TETRA' sim static --minutes 3000 --rate-hz 100 -o sig_$sig.h5 2>/dev/null & p=\$!;
     for i in \$(seq 200); do ls -A | grep -q '^\\.sig_$sig.h5.tetra-' && break; sleep 0.05; done;
     kill -$sig \$p; wait \$p; st=\$?; test \$st -gt 128 && test \"\$(cat sig_$sig.h5)\" = previous && ! ls -A | grep -q tetra-"
done
# The same for convert and replay (a 400 000-row log: they run long enough to be signalled mid-write).
"$TETRA" sim static --minutes 33.4 --rate-hz 200 -o long.csv 2>/dev/null || { echo "fixture: long log failed"; exit 1; }
echo previous >sig_conv.h5
echo previous >sig_att.csv
check_sh outputs "SIGTERM during convert: no temporary file, previous output kept" \
  "set -m; '$TETRA' convert long.csv sig_conv.h5 2>/dev/null & p=\$!;
   for i in \$(seq 1000); do ls -A | grep -q '^\\.sig_conv.h5.tetra-' && break; sleep 0.01; done;
   kill -TERM \$p; wait \$p; st=\$?; test \$st -gt 128 && test \"\$(cat sig_conv.h5)\" = previous && ! ls -A | grep -q tetra-"
check_sh outputs "SIGINT during replay: no temporary file, previous outputs kept" \
  "set -m; '$TETRA' replay long.csv --calibration $CAL --attitude sig_att.csv --events sig_ev.jsonl 2>/dev/null & p=\$!;
   for i in \$(seq 1000); do ls -A | grep -q '^\\.sig_att.csv.tetra-' && break; sleep 0.01; done;
   kill -INT \$p; wait \$p; st=\$?; test \$st -gt 128 && test \"\$(cat sig_att.csv)\" = previous && test ! -e sig_ev.jsonl && ! ls -A | grep -q tetra-"
rm -f long.csv
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
printf 'pipeline:\n  onset_sigma: abc\n' >badnum.yaml
check yaml "bad number names the key" 2 "badnum.yaml:2: pipeline.onset_sigma: 'abc' is not a number" "" -- \
  replay "$LOG" --calibration "$CAL" --config badnum.yaml --attitude a.csv --events e.jsonl
printf 'pipeline:\n  stuck_repeat_count: 3\n' >constant.yaml
check yaml "a fixed design constant set in a file names it" 2 \
  "constant.yaml:2: pipeline.stuck_repeat_count: a fixed design constant \(10 samples\)" "" -- \
  replay "$LOG" --calibration "$CAL" --config constant.yaml --attitude a.csv --events e.jsonl
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

sed 's/^# latitude_deg=.*/# latitude_deg=-23,2/' "$TT" >commalat.csv
grep -q 'latitude_deg=-23,2' commalat.csv || sed -i '1i # latitude_deg=-23,2' commalat.csv
check csv "decimal comma in the latitude comment" 2 "commalat.csv: comment '# latitude_deg=-23,2' is not a decimal number" "" -- \
  calibrate commalat.csv -o c.yaml
awk -F, -v OFS=, '/^#/ || /^time_s/ { print; next } { $1 = sprintf("%.6f", $1 + 1e10); print }' "$LOG" >bigtime.csv
check csv "times near 1e10 s" 2 "bigtime.csv:$first_row: column 'time_s': time 1e\+10 s is beyond" "" -- \
  replay bigtime.csv --calibration "$CAL" --attitude a.csv --events e.jsonl
cal_with '0,/scale_factor_V_per_dps:/s/scale_factor_V_per_dps: .*/scale_factor_V_per_dps: 1e-320/' denormal.yaml
check yaml "denormal scale factor 1e-320" 2 "denormal.yaml:[0-9]+: gyros\[0\].scale_factor_V_per_dps: must be a number with magnitude" "" -- \
  replay "$LOG" --calibration denormal.yaml --attitude a.csv --events e.jsonl
printf '{"time_s": 1, "command": "exclude", "gyro": 2, "gyro": 3}\n' >dupcmd.jsonl
check inputs "commands: a key twice" 2 "dupcmd.jsonl:1: field 'gyro' appears twice" "" -- \
  replay "$LOG" --calibration "$CAL" --commands dupcmd.jsonl --attitude a.csv --events e.jsonl
printf '{"time_s": 1, "command": "exclude", "gyro": 2.5}\n' >fraccmd.jsonl
check inputs "commands: gyro 2.5" 2 "fraccmd.jsonl:1: field 'gyro' must be a whole number" "" -- \
  replay "$LOG" --calibration "$CAL" --commands fraccmd.jsonl --attitude a.csv --events e.jsonl
if "$TETRA" help fusion >/dev/null 2>&1; then  # a build with DDS
printf 'unit: "tetra\\n1"\ncalibration: %s\n' "$CAL" >nlunit.yaml
check yaml "fusion unit name with a newline" 2 "nlunit.yaml:1: unit: contains a control character" "" -- \
  fusion --config nlunit.yaml
printf 'unit: "tetra\xff"\ncalibration: %s\n' "$CAL" >utfunit.yaml
check yaml "fusion unit name not UTF-8" 2 "utfunit.yaml:1: unit: is not valid UTF-8" "" -- \
  fusion --config utfunit.yaml
fi

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
check options "--initial-q empty" 2 "--initial-q: expected four numbers" "" -- replay "$LOG" --calibration "$CAL" --initial-q '' --attitude a.csv --events e.jsonl
"$TETRA" help fusion >/dev/null 2>&1 &&
  check options "sim --dds-unit with a newline" 2 "--dds-unit: unit name: contains a control character" "" -- \
    sim static --minutes 0.1 --dds --dds-unit $'a\nb'
check options "--initial-q hexadecimal" 2 "--initial-q" "" -- replay "$LOG" --calibration "$CAL" --initial-q 0x1,0,0,0 --attitude a.csv --events e.jsonl
check options "--dt-tolerance out of range" 2 "--dt-tolerance" "" -- allan "$LOG" --dt-tolerance 3
check options "--gyro hexadecimal" 2 "--gyro" "" -- allan "$LOG" --gyro 0x1

# --- values: bounded work, physical ranges ----------------------------------------------------------
# A campaign spec (open loop, the built-in orbit) with its lines replaced: spec_with FILE 'YAML lines'.
spec_with() { printf 'loop: open\nscenarios: [orbit]\n%b' "$2" >"$1"; }
awk 'BEGIN { printf "loop: open\nscenarios: [orbit]\nkinds: [stuck]\ngyros: [1]\nduration_s: 30000\nonsets_s: [";
  for (i = 1; i <= 20000; ++i) printf "%s%d", (i > 1 ? ", " : ""), i; printf "]\nseeds: [";
  for (i = 0; i < 20000; ++i) printf "%s%d", (i > 0 ? ", " : ""), i; print "]" }' >bigspec.yaml
check values "campaign: 20,000 onsets x 20,000 seeds (258 KB)" 2 \
  "bigspec.yaml: the matrix has 400000000 runs .*onsets_s 20000.*seeds 20000.*more than 1000000" "" -- \
  campaign bigspec.yaml --out camp
spec_with nan_onset.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [.nan]\nseeds: [1]\n'
check values "campaign: onsets_s [.nan]" 2 "nan_onset.yaml:5: onsets_s\[0\]: '.nan' is not a number" "" -- \
  campaign nan_onset.yaml --out camp
spec_with neg_onset.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [-10]\nseeds: [1]\n'
check values "campaign: onsets_s [-10]" 2 "neg_onset.yaml:5: onsets_s\[0\]: must not be negative" "" -- \
  campaign neg_onset.yaml --out camp
spec_with late_onset.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [7000]\nseeds: [1]\n'
check values "campaign: an onset after the end" 2 "late_onset.yaml:5: onsets_s\[0\]: 7000 s is at or after the end" "" -- \
  campaign late_onset.yaml --out camp
spec_with long.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\nduration_s: 1e300\n'
check values "campaign: duration_s 1e300" 2 "long.yaml:7: duration_s: .*duration_s must be above 0" "" -- \
  campaign long.yaml --out camp
spec_with nan_size.yaml 'kinds: [bias]\nsizes: {bias: [.nan]}\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n'
check values "campaign: sizes {bias: [.nan]}" 2 "nan_size.yaml:4: sizes.bias\[0\]: '.nan' is not a number" "" -- \
  campaign nan_size.yaml --out camp
spec_with big_size.yaml 'kinds: [bias]\nsizes: {bias: [1e309]}\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n'
check values "campaign: sizes {bias: [1e309]}" 2 "big_size.yaml:4: sizes.bias\[0\]: " "" -- \
  campaign big_size.yaml --out camp
spec_with unrun_size.yaml 'kinds: [stuck]\nsizes: {bias: [0.01]}\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n'
check values "campaign: sizes for a kind not run" 2 "unrun_size.yaml:4: sizes.bias: kind bias is not in kinds" "" -- \
  campaign unrun_size.yaml --out camp
spec_with dup_gyro.yaml 'kinds: [stuck]\ngyros: [1, 1]\nonsets_s: [60]\nseeds: [1]\n'
check values "campaign: gyros [1, 1]" 2 "dup_gyro.yaml:4: gyros\[1\]: the same value as gyros\[0\]" "" -- \
  campaign dup_gyro.yaml --out camp
spec_with neg_seed.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [-1]\n'
check values "campaign: seeds [-1]" 2 "neg_seed.yaml:6: seeds\[0\]: expected a whole number from 0 to" "" -- \
  campaign neg_seed.yaml --out camp
spec_with maybe.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\nfault_free: maybe\n'
check values "campaign: fault_free maybe" 2 "maybe.yaml:7: fault_free: expected true or false, got 'maybe'" "" -- \
  campaign maybe.yaml --out camp
printf 'unit: flat\ngyros:\n' >flat_unit.yaml
for a in '[1, 0, 0]' '[0, 1, 0]' '[0.6, 0.8, 0]' '[0.8, -0.6, 0]'; do
  printf '  - {id: %d, scale_factor_V_per_dps: 0.08, bias_V: 0, axis: %s, noise: {arw_dps_rtHz: 3e-5}}\n' \
    "$(($(grep -c 'id:' flat_unit.yaml) + 1))" "$a" >>flat_unit.yaml
done
printf 'scenario: orbit\nunit: flat_unit.yaml\n' >flat_orbit.yaml
spec_with flat.yaml 'kinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\nduration_s: 120\n'
sed -i 's/^scenarios: .*/scenarios: [orbit, flat_orbit.yaml]/' flat.yaml
# A unit the pipeline cannot run is no bad spec: its runs are error rows, the campaign completes.
check values "campaign: a scenario with coplanar gyro axes: error rows" 0 "" \
  "camp_flat camp_flat/runs.csv camp_flat/spec.yaml camp_flat/spec.sha256 camp_flat/shard.txt" -- \
  campaign flat.yaml --out camp_flat --no-report
grep -q '^1,flat_orbit.yaml,stuck,1,60,0,1,error,.*span three dimensions$' camp_flat/runs.csv ||
  { echo "FAIL campaign: coplanar unit's row is not an error row naming why"; fail=$((fail + 1)); }
printf 'scenario: orbit\nclosed_loop:\n  inertia_kg_m2: [1e-300, 1e-300, 1e-300]\n' >tiny_inertia.yaml
check values "closed loop: inertia 1e-300" 2 "tiny_inertia.yaml:3: closed_loop: inertia_kg_m2 principal moments" "" -- \
  sim tiny_inertia.yaml --closed-loop
printf 'scenario: orbit\nclosed_loop:\n  inertia_kg_m2: [1e300, 1e300, 1e300]\n' >huge_inertia.yaml
check values "closed loop: inertia 1e300" 2 "huge_inertia.yaml:3: closed_loop: inertia_kg_m2 principal moments" "" -- \
  sim huge_inertia.yaml --closed-loop
printf 'scenario: orbit\nclosed_loop:\n  inertia_kg_m2: [1, 1, 5]\n' >triangle.yaml
check values "closed loop: inertia breaking the triangle inequality" 2 "triangle.yaml:3: .*triangle inequality" "" -- \
  sim triangle.yaml --closed-loop
printf 'scenario: orbit\nclosed_loop:\n  disturbance: {constant_Nm: [1e300, 0, 0]}\n' >torque.yaml
check values "closed loop: a 1e300 disturbance" 2 "torque.yaml:3: closed_loop: disturbance.constant_Nm\[0\] must be" "" -- \
  sim torque.yaml --closed-loop
printf 'scenarios: [huge_inertia.yaml]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n' >inertia_spec.yaml
check values "campaign: a scenario with inertia 1e300" 2 "inertia_spec.yaml:1: scenarios\[0\]: .*inertia_kg_m2" "" -- \
  campaign inertia_spec.yaml --out camp
check values "sim --acs-amplitude 1e300" 2 "--acs-amplitude: '1e300' must be from 0 to 45" "" -- \
  sim orbit --minutes 0.1 --acs-amplitude 1e300 -o s.csv
check values "sim --orbit-period 1e-300" 2 "--orbit-period: '1e-300' must be from 20 to" "" -- \
  sim orbit --minutes 0.1 --orbit-period 1e-300 -o s.csv
check values "sim --minutes inf" 2 "^tetra sim: --minutes: 'inf' must be above 0 and at most 1e\+07 .{0,40}$" "" -- \
  sim orbit --minutes inf -o s.csv
if "$TETRA" sim --help | grep -q -- '--speed'; then  # built with DDS
  check values "sim --dds --speed 1e-300" 2 "--speed: '1e-300' must be 0 \(as fast as possible\) or at least 0.001" "" -- \
    sim orbit --dds --speed 1e-300
  check values "sim --dds --wait-timeout 1e300" 2 "--wait-timeout: '1e300' must be above 0 and at most 86400" "" -- \
    sim orbit --dds --wait-timeout 1e300
fi
printf 'scenario: orbit\norbit_period_s: 1e-300\n' >period.yaml
check values "scenario orbit_period_s 1e-300" 2 "period.yaml:2: orbit_period_s must be from 1200 to" "" -- \
  sim period.yaml --minutes 0.1 -o s.csv

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

# --- the newer surfaces: play, ingest, ground accounts (docs/reliability.md, "Round 4") ---------------
# Refused before DDS is opened, or ended at once: never a sleep through a far-future row, never a read of
# a socket as standard input, never a unit key fusion refuses, never a users file replaced or opened up.
printf 'time_s,g1,g2,g3\n0,1,2,3\n0.1,1,2,3\n1000000,1,2,3\n' >far.csv
check surfaces "play: a row 1e6 s ahead (it slept 1e5 s)" 2 "far.csv:4: time 1e\+06 s is 999999.9 s after" "" -- \
  play far.csv --domain 229 --wait-timeout 1
printf '# unit=caf\xe9\ntime_s,g1,g2,g3\n0,1,2,3\n0.1,1,2,3\n' >cafe.csv
check surfaces "play: '# unit=' not UTF-8" 2 "cafe.csv.*(UTF-8|unit)" "" -- play cafe.csv --domain 229 --wait-timeout 1
printf '# unit=a%%0Ab\ntime_s,g1,g2,g3\n0,1,2,3\n0.1,1,2,3\n' >nl_unit.csv
check surfaces "play: '# unit=' with a newline" 2 "nl_unit.csv: the unit name of '# unit=': contains a control" "" -- \
  play nl_unit.csv --domain 229 --wait-timeout 1
printf '# unit=\ntime_s,g1,g2,g3\n0,1,2,3\n0.1,1,2,3\n' >empty_unit.csv
check surfaces "play: '# unit=' empty" 2 "empty_unit.csv: the unit name of '# unit=': must have 1 to 31 bytes" "" -- \
  play empty_unit.csv --domain 229 --wait-timeout 1
check_sh surfaces "ingest with standard input closed ends (it read a DDS socket)" \
  "\"$TETRA\" ingest --wait-readers 0 --domain 229 -q <&- >/dev/null 2>&1"
check_sh surfaces "ground passwd writes through a symlinked users file" \
  "printf 'correct horse\\n' | \"$TETRA\" ground passwd alice --users real_users --password-stdin >/dev/null &&
   ln -s real_users link_users &&
   printf 'battery staple\\r\\n' | \"$TETRA\" ground passwd bob --users link_users --password-stdin >/dev/null &&
   [ -L link_users ] && grep -q '^alice:' real_users && grep -q '^bob:' real_users"
check_sh surfaces "ground passwd refuses a 10 MB password" \
  "head -c 10000000 /dev/zero | tr '\\0' x | \"$TETRA\" ground passwd carol --users real_users --password-stdin 2>err_pw;
   [ \$? = 2 ] && grep -q 'at most 1024 characters' err_pw && ! grep -q '^carol:' real_users"
ln -s gone_users dangling_users
check_sh surfaces "ground passwd refuses a users file linked to nothing" \
  "printf 'correct horse\\n' | \"$TETRA\" ground passwd dave --users dangling_users --password-stdin 2>err_dl;
   [ \$? = 2 ] && [ \$(wc -l <err_dl) = 1 ] && grep -q 'dangling_users: a symbolic link to no file' err_dl &&
   [ -L dangling_users ] && [ ! -e gone_users ]"
chmod 644 real_users 2>/dev/null
check surfaces "ground on a users file others can read" 2 "real_users: the accounts file is readable or writable by group or others \\(mode 0644\\)" "" -- \
  ground --listen 127.0.0.1:0 --users real_users --domain 229
printf 'alice:commander:$argon2id$v=19$m=65536,t=2,p=1$cut\n' >cut_users && chmod 600 cut_users
check surfaces "ground on a users file with a damaged hash" 2 "cut_users:1: the argon2id hash is damaged" "" -- \
  ground --listen 127.0.0.1:0 --users cut_users --domain 229

# A TDMS log's channel map (LOG.channels.yaml beside it) is read only as a regular file: a FIFO blocked the
# read until a writer came, a link to nothing was taken for no map.
python3 "$SRC/tests/tdms/make_tdms.py" "$LOG" maps.tdms --one-segment >/dev/null 2>&1 ||
  { echo "fixture: make_tdms.py failed"; exit 1; }
mkfifo maps.channels.yaml
check surfaces "convert: a channel map that is a FIFO" 2 "maps.channels.yaml: the channel map of maps.tdms is a FIFO" "" -- \
  convert maps.tdms maps.csv
rm maps.channels.yaml && mkdir maps.channels.yaml
check surfaces "convert: a channel map that is a folder" 2 "maps.channels.yaml: the channel map of maps.tdms is a folder" "" -- \
  convert maps.tdms maps.csv
rmdir maps.channels.yaml && ln -s gone.yaml maps.channels.yaml
check surfaces "convert: a channel map linked to nothing" 2 "maps.channels.yaml: the channel map of maps.tdms is a symbolic link to no file" "" -- \
  convert maps.tdms maps.csv
rm maps.channels.yaml

# --- summary -----------------------------------------------------------------------------------------
echo
for c in "${!class_count[@]}"; do printf '%s %d\n' "$c" "${class_count[$c]}"; done | sort
echo "robustness: $pass passed, $fail failed, $((pass + fail)) cases"
for f in "${failures[@]}"; do echo "FAIL $f"; done
((fail == 0))
