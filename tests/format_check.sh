#!/usr/bin/env bash
# The C sources are formatted by clang-format 14 (Debian 12) with the repository's .clang-format.
set -eu
cd "$(dirname "$0")/.."
version=$(clang-format --version)
case "$version" in
  *"version 14."*) ;;
  *) echo "format check needs clang-format 14, found: $version"; exit 1 ;;
esac
clang-format --dry-run --Werror solver/*.c solver/*.h solver/*/*.c solver/*/*.h stats/*.c stats/*.h restart/*.c restart/*.h \
  tests/*.c tests/*.h
echo "all C sources formatted"
