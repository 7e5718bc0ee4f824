#!/usr/bin/env bash
# Wall time (whole process) of one study (default: bench/studies/hh-scaling-480.json) with
# --jobs 1 and 2 and under mpirun -np 1 and 2, REPS rounds (the best of each is kept), with its table checked against
# the --jobs 1 table (timings aside). Numbers for docs/benchmarks/studies-over-ranks.md.
#   bench/scaling_study.sh [STUDY.json] [REPS] [OUT]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
study="${1:-$root/bench/studies/hh-scaling-480.json}"
reps="${2:-2}"
out="${3:-$root/out/scaling}"
tsi="$root/build/bin/tsi"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl=self,vader OMPI_MCA_btl_vader_single_copy_mechanism=none
mkdir -p "$out"
table() { /usr/bin/python3 -c '
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
w = rows[0].index("wall_seconds")
print("\n".join(",".join(r[:w] + r[w + 1:]) for r in rows))' "$1/table.csv"; }
# The four set-ups take turns, REPS rounds, and each keeps its best wall time: the machine may
# be shared, and a slow round then slows every set-up alike rather than one.
declare -A best
run() {  # run NAME COMMAND...: one timed run into $out/NAME
  local name="$1"; shift
  rm -rf "${out:?}/$name"
  /usr/bin/time -o "$out/time" -f "%e" "$@" --out "$out/$name" --no-plots >/dev/null 2>&1 || true
  local t; t=$(tail -1 "$out/time")
  if [ -z "${best[$name]:-}" ] || /usr/bin/python3 -c "import sys; sys.exit(0 if $t < ${best[$name]} else 1)"; then
    best[$name]=$t
  fi
}
for _ in $(seq "$reps"); do
  run jobs1 "$tsi" study "$study" --jobs 1
  run jobs2 "$tsi" study "$study" --jobs 2
  run mpi1 mpirun -np 1 --oversubscribe --allow-run-as-root "$tsi" study "$study"
  run mpi2 mpirun -np 2 --oversubscribe --allow-run-as-root "$tsi" study "$study"
done
j1=${best[jobs1]} j2=${best[jobs2]} m1=${best[mpi1]} m2=${best[mpi2]}
for d in jobs2 mpi1 mpi2; do
  if [ "$(table "$out/jobs1")" == "$(table "$out/$d")" ]; then same="same table"; else same="TABLE DIFFERS"; fi
  echo "$d: $same as jobs1"
done
/usr/bin/python3 - "$j1" "$j2" "$m1" "$m2" <<'PY'
import sys
j1, j2, m1, m2 = map(float, sys.argv[1:])
print(f"--jobs 1      {j1:8.2f} s")
print(f"--jobs 2      {j2:8.2f} s  speed-up {j1 / j2:.2f}  efficiency {j1 / j2 / 2:.0%}")
print(f"mpirun -np 1  {m1:8.2f} s  ({m1 / j1:.2f} x --jobs 1)")
print(f"mpirun -np 2  {m2:8.2f} s  speed-up {m1 / m2:.2f} over -np 1, {j1 / m2:.2f} over --jobs 1  efficiency {j1 / m2 / 2:.0%}")
PY
