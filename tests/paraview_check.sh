#!/usr/bin/env bash
# ParaView opens the particle snapshots of RUN_DIR with visible points (issue 13, point 11):
# tests/paraview_check.py under xvfb-run pvpython. ParaView is not part of jobs/setup.sh (a large
# package): without pvpython and xvfb-run the test is skipped (exit 77, ctest SKIP_RETURN_CODE).
# Install with: apt-get install paraview python3-paraview xvfb xauth
# usage: paraview_check.sh RUN_DIR PNG [--les]
command -v pvpython > /dev/null && command -v xvfb-run > /dev/null || {
  echo "SKIP: pvpython or xvfb-run not installed (apt-get install paraview python3-paraview xvfb xauth)"
  exit 77
}
exec xvfb-run -a -s "-screen 0 1280x1024x24" pvpython "$(dirname "$0")/paraview_check.py" "$@"
