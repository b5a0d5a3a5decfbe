#!/usr/bin/env bash
# Issue 26, points 1 and 2: init.from refuses a particles.nc that is not a state of the box,
# before reading past a buffer or starting a run: a variable longer than the 'particle'
# dimension (long) or 2-D (twod), no particles (empty), a repeated id (dupid), a negative
# density (negrho), a position outside the box (outside). Exit 1, a message naming the file
# and what is wrong, no run directory content written.
# usage: init_from_bad.sh CHANSPH SCENE RUNS PYTHON CASE
set -u
chansph=$1 scene=$2 runs=$3 py=$4 case=$5
d=$runs/init_from_bad_$case
src=$runs/init_from_bad.src
rm -rf "$d" "$d.nc"
if [ ! -e "$src/particles.nc" ]; then
  rm -rf "$src.$$"
  "$chansph" run "$scene" --out "$src.$$" --set time.t_end=0.05 --set output.t_average_start=0 \
    > /dev/null || { echo "FAIL: source run"; exit 1; }
  mv -T "$src.$$" "$src" 2> /dev/null || rm -rf "$src.$$" # another case made it meanwhile
fi
# the source as text (CDL), edited, and back to netCDF-4; or edited in place with h5py
cdl_edit() {
  ncdump "$src/particles.nc" | "$py" -c "
import re, sys
t, case = sys.stdin.read(), sys.argv[1]
n = int(re.search(r'particle = (\d+) ;', t).group(1))
if case == 'long':    # u over a dimension ten times longer than 'particle'
    t = t.replace('particle = %d ;' % n, 'particle = %d ;\n\tbig = %d ;' % (n, 10 * n))
    t = t.replace('double u(particle) ;', 'double u(big) ;')
    t = re.sub(r'\n u = [^;]*;', '\n u = ' + ', '.join(['1'] * (10 * n)) + ' ;', t)
elif case == 'twod':  # u over (particle, two)
    t = t.replace('particle = %d ;' % n, 'particle = %d ;\n\ttwo = 2 ;' % n)
    t = t.replace('double u(particle) ;', 'double u(particle, two) ;')
    t = re.sub(r'\n u = [^;]*;', '\n u = ' + ', '.join(['1'] * (2 * n)) + ' ;', t)
elif case == 'empty': # the dimension 'particle' of length 0, no data
    t = t.replace('particle = %d ;' % n, 'particle = UNLIMITED ;')
    t = t[:t.index('data:')] + '}'
sys.stdout.write(t)
" "$case" | ncgen -k nc4 -o "$d.nc" || { echo "FAIL: cannot make the source"; exit 1; }
}
h5_edit() {
  cp "$src/particles.nc" "$d.nc"
  "$py" -c "
import h5py, sys
with h5py.File(sys.argv[1], 'r+') as f:
    exec(sys.argv[2])
" "$d.nc" "$1" || { echo "FAIL: cannot edit the source"; exit 1; }
}
case $case in
  long) cdl_edit && re="variable 'u' is not 1-D over dimension 'particle' \(380\)" ;;
  twod) cdl_edit && re="variable 'u' is not 1-D over dimension 'particle' \(380\)" ;;
  empty) cdl_edit && re="no particles: not a usable initial state" ;;
  dupid) h5_edit "f['id'][5] = f['id'][6]" &&
    re="particle id [0-9]+ repeated: the ids must be 0..379, each once" ;;
  negrho) h5_edit "f['rho'][7] = -f['rho'][7]" &&
    re="variable 'rho' of particle id [0-9]+ is not positive \(-[0-9.e+]+\)" ;;
  outside) h5_edit "f['x'][7] = 1.5 * f['x'][7] + 1.0" &&
    re="variable 'x' of particle id [0-9]+ is outside the box \[0, 1\) x \(0, 1\) \([0-9.e+]+\)" ;;
  *) echo "unknown case $case"; exit 2 ;;
esac
"$(dirname "$0")/expect_fail.sh" 1 "init_from_bad_$case.nc \\(init.from\\): $re" \
  "$chansph" run "$scene" --out "$d" --set "init.from=$d.nc" || exit 1
# nothing of a run was written
if compgen -G "$d/*.nc" > /dev/null || compgen -G "$d/checkpoints/*" > /dev/null; then
  echo "FAIL: the refused run wrote files: $(ls "$d")"
  exit 1
fi
