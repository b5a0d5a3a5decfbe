#!/usr/bin/env bash
# budget_test.sh CHANSPH SCENE RUNS NAME TOL [--laminar|--unsteady] [--rs-identity T |
#   --rs-laminar T | --rs-closure T] [-- chansph --set args...]
# Runs SCENE into RUNS/budget_NAME and checks its momentum budget (tests/budget_check.py) and,
# with an --rs-* option, its Reynolds-stress budgets (tests/rs_budget_check.py --identity T ...).
set -uo pipefail
chansph=$1 scene=$2 runs=$3 name=$4 tol=$5
shift 5
check=() rs=()
case "${1:-}" in --laminar | --unsteady) check=("$1") && shift ;; esac
case "${1:-}" in --rs-identity | --rs-laminar | --rs-closure) rs=("--${1#--rs-}" "$2") && shift 2 ;; esac
[ "${1:-}" = -- ] && shift
out=$runs/budget_$name
"$chansph" run "$scene" --out "$out" --overwrite "$@" > "$out.log" 2>&1 ||
  { tail "$out.log"; echo "FAIL: run"; exit 1; }
grep "^stats:" "$out.log" | tail -n 1
/usr/bin/python3 "$(dirname "$0")/budget_check.py" "$out/stats.nc" --tol "$tol" "${check[@]}" ||
  exit 1
[ ${#rs[@]} -eq 0 ] || /usr/bin/python3 "$(dirname "$0")/rs_budget_check.py" "$out/stats.nc" "${rs[@]}"
