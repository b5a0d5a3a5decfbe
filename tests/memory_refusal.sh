#!/usr/bin/env bash
# Issue 26 point 7: a scene whose particles do not fit in this machine's memory is refused before
# anything is allocated (exit 1, the keys and the sizes named, the output directory untouched),
# rather than killed by the OOM killer minutes later. The spacing of jobs/scenes/poiseuille3d.ini
# (0.4 x 1 x 0.4 m; 0.2 m / k, so that the box holds whole layers) is chosen from this machine's MemTotal so that the lattice holds about one
# particle per kB of memory: above the 80% limit at the ~1 kB per particle of the estimate (20 M
# particles on the 24 GB machine the issue was found on).
# usage: memory_refusal.sh CHANSPH SCENES
set -u
chansph=$1 scenes=$2
kb=$(awk '/^MemTotal:/ {print $2}' /proc/meminfo)
dr=$(/usr/bin/python3 -c "import math; print(0.2 / math.ceil(0.2 / (0.16 / $kb) ** (1 / 3)))") # 0.2 m / k
echo "MemTotal $kb kB: domain.dr = $dr (about $kb particles)"
exec "$(dirname "$0")/scene_error.sh" "$chansph" "$scenes/poiseuille3d.ini" \
  "keys 'domain.lx', 'domain.delta', 'domain.lz', 'domain.dr': .* particles need at least .* GB per MPI rank .* more than the .* GB \(80%\) of the .* GB of memory of this machine" \
  --set domain.dr="$dr"
