#!/usr/bin/env bash
# Issue 26, point 9: every user-facing Python tool (stats/python/chansph-stats TOOL, the check
# scripts of tests/, jobs/states/reduce_state.py) refuses bad input in the C side's style:
# exit status 1, a first line "error: ..." on stderr naming the file or argument (then at most
# the usage), no Python traceback. Bad inputs: a missing file, a file that is not netCDF or
# HDF5, a netCDF file without the needed variables (particles.nc for stats.nc and the reverse),
# a stats.nc with 0 windows, bad numeric arguments.
# usage: py_input_errors.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
root=$(cd "$(dirname "$0")/.." && pwd)
py=/usr/bin/python3
tool=$root/stats/python/chansph-stats
dns=$root/stats/dns/mkm1999/chan180.means
w=$runs/py_input_errors
rm -rf "$w" && mkdir -p "$w" || exit 1
status=0
fail() { echo "FAIL: $*"; status=1; }

# a run with 0 averaging windows: stats.nc, particles.nc, log.txt, a checkpoint
run=$w/nowin
"$chansph" run "$scene" --out "$run" --overwrite --set time.t_end=0.05 \
  --set output.t_average_start=0.05 --set output.stats_every=100000 > "$w/run.log" 2>&1 ||
  { cat "$w/run.log"; exit 1; }
nowin=$run/stats.nc part=$run/particles.nc
ckpt=$(ls "$run"/checkpoints/ckpt_*.h5 | tail -n 1)
echo "not netCDF" > "$w/text.nc"
echo "not HDF5" > "$w/text.h5"
cp "$w/text.nc" "$w/text.txt"
missing=$w/missing.nc

# expect NAME REGEX command...: exit 1, stderr "error: ..." matching REGEX then only the usage
expect() {
  local name=$1 regex=$2
  shift 2
  "$@" > "$w/$name.out" 2> "$w/$name.err"
  local rc=$? first
  first=$(head -n 1 "$w/$name.err")
  echo "$name: exit $rc: $first"
  [ $rc -eq 1 ] || fail "$name: exit status $rc, expected 1"
  echo "$first" | grep -Eq -- "^error: .*$regex" ||
    fail "$name: first line is not 'error: ...$regex'"
  tail -n +2 "$w/$name.err" | grep -Evq '^(usage: |  )' &&
    fail "$name: more than the error line and the usage on stderr: $(tail -n +2 "$w/$name.err")"
  cat "$w/$name.out" "$w/$name.err" | grep -q Traceback && fail "$name: a Python traceback"
}

# the analysis tools (stats/python/chansph_stats)
expect tool_unknown "unknown tool 'nosuch'" "$tool" nosuch
expect windows_missing "missing.nc: cannot open: No such file" "$tool" windows "$missing"
expect windows_not_netcdf "text.nc: cannot open as netCDF" "$tool" windows "$w/text.nc"
expect windows_no_group "particles.nc: no group 'eulerian'" "$tool" windows "$part"
expect windows_no_window "stats.nc: no averaging window" "$tool" windows "$nowin"
expect windows_every_0 "argument --every: 0: must be at least 1" "$tool" windows "$nowin" --every 0
expect windows_every_x "argument --every: 'x' is not an integer" "$tool" windows "$nowin" --every x
expect windows_u_tau "argument --u-tau: -1: must be at least 0" "$tool" windows "$nowin" --u-tau -1
expect ab_table_missing "missing/stats.nc: cannot open: No such file" "$tool" ab_table "$w/missing"
expect summary_missing "missing.nc: cannot open statistics file: No such file" "$tool" summary "$missing" --dns "$dns"
expect summary_not_netcdf "text.nc: cannot open as netCDF" "$tool" summary "$w/text.nc" --dns "$dns"
expect summary_no_var "particles.nc: no variable 'y_mean'" "$tool" summary "$part" --dns "$dns"
expect summary_no_window "stats.nc: no positive u_tau" "$tool" summary "$nowin" --dns "$dns"
expect summary_long_missing "missing.nc: cannot open statistics file" "$tool" summary "$nowin" --dns "$dns" --long "$missing"
expect figures_missing "missing.nc: cannot open statistics file: No such file" "$tool" figures "$missing"
expect figures_no_var "particles.nc: no variable 'y_mean'" "$tool" figures "$part"
expect figures_no_window "stats.nc: no positive u_tau" "$tool" figures "$nowin"
expect ab_table_no_window "stats.nc: no averaging window" "$tool" ab_table "$run"
expect lagr_table_missing "missing.nc: cannot open: No such file" "$tool" lagr_table "$missing"
expect lagr_table_not_netcdf "text.nc: cannot open as netCDF" "$tool" lagr_table "$w/text.nc"
expect lagr_table_no_group "particles.nc: no lagrangian or quadrants group" "$tool" lagr_table "$part"
expect lagr_table_lags "argument --lags: -1: must be larger than 0" "$tool" lagr_table "$nowin" \
  --lags 18 -1
expect ab_table_from "argument --from: 'x' is not a number" "$tool" ab_table "$run" --from x
expect window_peaks_spec "nowin: expected LABEL=RUN_DIR" "$tool" window_peaks --dns "$dns" "$run"
expect window_peaks_span "A=.*@2:1: 2:1: expected T0:T1 with T0 <= T1" "$tool" window_peaks \
  --dns "$dns" "A=$run@2:1"
expect window_peaks_dns "missing.nc: no such file" "$tool" window_peaks --dns "$missing" \
  "A=$run@0:1"
expect blocking_spec "nowin: expected LABEL=RUN_DIR" "$tool" blocking "$run"
expect blocking_no_window "stats.nc: no averaging window" "$tool" blocking "A=$run@0:1"
expect blocking_missing "missing/stats.nc: cannot open: No such file" "$tool" blocking \
  "A=$w/missing@0:1"
expect error_vs_time_group "argument --group: 0: must be larger than 0" "$tool" error_vs_time \
  --dns "$dns" --group 0 "A=$run"
expect error_vs_time_run "missing/log.txt" "$tool" error_vs_time --dns "$dns" "A=$w/missing"
expect resolution_dr "argument --developed-dr: -3: must be larger than 0" "$tool" \
  resolution_extrapolate --dns "$dns" --developed "$run" --developed-dr -3 "6=$run" "9=$run"
expect resolution_window "argument --window: 2:1: expected T0:T1 with T0 <= T1" "$tool" \
  resolution_extrapolate --dns "$dns" --developed "$run" --developed-dr 3 --window 2:1 "6=$run"
expect plot_profile_missing "missing.nc: cannot open: No such file" "$tool" plot_profile "$missing"
expect plot_profile_not_netcdf "text.nc: cannot open as netCDF" "$tool" plot_profile "$w/text.nc"
expect plot_profile_no_var "particles.nc: no variable 'y_mean'" "$tool" plot_profile "$part"
expect plot_profile_no_window "stats.nc: u_mean has no value" "$tool" plot_profile "$nowin" \
  -o "$w/profile.png"
expect pdf_compare_missing "missing.nc: cannot open: No such file" "$tool" pdf_compare "$missing"
expect pdf_compare_not_netcdf "text.nc: cannot open as netCDF" "$tool" pdf_compare "$w/text.nc"
expect pdf_compare_no_group "stats.nc: no group 'pdfs'" "$tool" pdf_compare "$nowin"
expect pdf_compare_dns "text.txt: no MKM PDF files" "$tool" pdf_compare "$nowin" --dns "$w/text.txt"
expect dns_c_table_missing "missing.nc: cannot open a Lee & Moser derived table: No such file" \
  "$tool" dns_c_table "$missing"
expect dns_c_table_text "text.txt: a Lee & Moser derived table holds 0 data row" "$tool" \
  dns_c_table "$w/text.txt"
expect ckpt_missing "missing.nc: cannot open: No such file" "$tool" ckpt "$missing"
expect ckpt_not_hdf5 "text.h5: cannot open as HDF5" "$tool" ckpt "$w/text.h5"
expect ckpt_foreign "stats.nc: not a chansph checkpoint" "$tool" ckpt "$nowin"
expect compare_no_var "particles.nc: no variable 'y_mean'" "$tool" compare "$part" --dns "$dns" \
  --out "$w/compare"
expect compare_max_error "argument --max-error: 'x' is not a number" "$chansph" compare "$nowin" \
  --dns "$dns" --max-error x
expect compare_no_window "stats.nc: no positive u_tau" "$chansph" compare "$nowin" --dns "$dns" \
  --out "$w/compare"

# the check scripts of tests/ and the state reducer of jobs/states/
t=$root/tests
expect ckpt_h5py_usage "the following arguments are required: RUN_DIR" $py "$t/ckpt_h5py_check.py"
expect ckpt_h5py_missing "missing: no checkpoints/ckpt_\*.h5" $py "$t/ckpt_h5py_check.py" \
  "$w/missing"
expect extract_check_usage "the following arguments are required" $py "$t/extract_check.py"
expect extract_check_missing "missing.nc: cannot open: No such file" $py "$t/extract_check.py" \
  "$chansph" "$missing"
expect extract_check_not_netcdf "text.nc: cannot open as netCDF" $py "$t/extract_check.py" \
  "$chansph" "$w/text.nc"
expect extract_check_no_var "particles.nc: no variable 'u_mean'" $py "$t/extract_check.py" \
  "$chansph" "$part"
expect extract_check_no_window "stats.nc: no averaging window" $py "$t/extract_check.py" \
  "$chansph" "$nowin"
expect budget_missing "missing.nc: cannot open: No such file" $py "$t/budget_check.py" "$missing" \
  --tol 1
expect budget_not_netcdf "text.nc: cannot open as netCDF" $py "$t/budget_check.py" "$w/text.nc" \
  --tol 1
expect budget_no_budget "particles.nc: no momentum budget" $py "$t/budget_check.py" "$part" --tol 1
expect budget_no_window "stats.nc: the budget has no value" $py "$t/budget_check.py" "$nowin" \
  --tol 1
expect budget_tol "argument --tol: 'x' is not a number" $py "$t/budget_check.py" "$nowin" --tol x
expect finite_usage "the following arguments are required: FILE" $py "$t/finite_check.py"
expect finite_missing "missing.nc: cannot open: No such file" $py "$t/finite_check.py" "$missing"
expect finite_not_netcdf "text.nc: cannot open as netCDF" $py "$t/finite_check.py" "$w/text.nc"
expect finite_not_hdf5 "text.h5: cannot open as HDF5" $py "$t/finite_check.py" "$w/text.h5"
expect cf_usage "the following arguments are required" $py "$t/cf_check.py"
expect cf_missing "missing.nc: cannot open: No such file" $py "$t/cf_check.py" "$missing"
expect cf_not_netcdf "text.nc: cannot open as netCDF" $py "$t/cf_check.py" "resumed:$w/text.nc"
r=$root/jobs/states/reduce_state.py
expect reduce_usage "the following arguments are required" $py "$r" "$part"
expect reduce_missing "missing.nc: cannot open: No such file" $py "$r" "$missing" "$w/state.nc"
expect reduce_not_netcdf "text.nc: cannot open as netCDF" $py "$r" "$w/text.nc" "$w/state.nc"
expect reduce_no_var "stats.nc: no variable 'id'" $py "$r" "$nowin" "$w/state.nc"
expect reduce_unwritable "nodir/state.nc: cannot create" $py "$r" "$part" "$w/nodir/state.nc"
tl=$root/jobs/states/tile_state.py
expect tile_usage "the following arguments are required" $py "$tl" "$part"
expect tile_missing "missing.nc: cannot open: No such file" $py "$tl" "$missing" "$part" "$w/t.nc"
expect tile_no_var "stats.nc: no variable 'id'" $py "$tl" "$nowin" "$part" "$w/t.nc"

# the good inputs are accepted (the checks refuse only what is wrong)
"$tool" ckpt "$ckpt" > /dev/null || fail "chansph-stats ckpt refused a checkpoint"
$py "$r" "$part" "$w/state.nc" || fail "reduce_state.py refused a particles.nc"
$py "$r" "$ckpt" "$w/state_ckpt.nc" || fail "reduce_state.py refused a checkpoint"
$py "$tl" "$w/state.nc" "$w/state_ckpt.nc" "$w/tiled.nc" --perturb 0.01 > /dev/null ||
  fail "tile_state.py refused two states of one run"
$py "$t/finite_check.py" --allow output/next_write "$ckpt" "$part" > /dev/null ||
  fail "finite_check.py refused finite files"
"$tool" --help > /dev/null || fail "chansph-stats --help: exit $?"
[ $status -eq 0 ] && echo PASS
exit $status
