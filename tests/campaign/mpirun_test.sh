#!/usr/bin/env bash
# `mpirun -np 2 autoshovel campaign`: two ranks share a 2-cycle campaign and store both cycles,
# the same rows a local run stores. Catches a binary whose MPI_Init is not Open MPI's: Ipopt's
# sequential MUMPS defines a do-nothing MPI_Init of its own, which once answered the call (see
# autoshovel_link_mpi_first in CMakeLists.txt).
#
#   mpirun_test.sh AUTOSHOVEL SOURCE_DIR
set -uo pipefail
autoshovel=$1 source_dir=$2
command -v mpirun >/dev/null || { echo "mpirun not installed: skipped"; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat >"$tmp/spec.yaml" <<'SPEC'
name: mpirun_check
scenario: cone_pile
seed: 4
weeks: 1
shifts_per_week: 2
cycles_per_shift: 1
policies: [auto]
SPEC
models=(--models "$source_dir/models")
mpirun --allow-run-as-root --oversubscribe -np 2 "$autoshovel" "${models[@]}" campaign \
  "$tmp/spec.yaml" -o "$tmp/mpi" >"$tmp/mpi.out" 2>&1 ||
  { cat "$tmp/mpi.out"; echo "FAIL: mpirun campaign exited non-zero"; exit 1; }
"$autoshovel" "${models[@]}" campaign "$tmp/spec.yaml" -o "$tmp/local" --workers 1 \
  >"$tmp/local.out" 2>&1 || { cat "$tmp/local.out"; echo "FAIL: local campaign"; exit 1; }
rows() { sqlite3 "$1" "select cycle, round(fill_rate, 9), round(time_total_s, 6) from cycles order by run_id, cycle"; }
mpi=$(rows "$tmp/mpi/results.sqlite") local=$(rows "$tmp/local/results.sqlite")
[ "$(echo "$mpi" | grep -c .)" -eq 2 ] || { echo "FAIL: $(echo "$mpi" | grep -c .) rows under mpirun"; exit 1; }
[ "$mpi" = "$local" ] || { echo "FAIL: rows differ"; echo "$mpi"; echo "$local"; exit 1; }
echo "mpirun_test: 2 ranks stored the 2 cycles a local run stores"
