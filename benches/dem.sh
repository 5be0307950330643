#!/usr/bin/env bash
# vibrobed beside soft-sphere DEM: LAMMPS (GRANULAR package, Debian's `lammps`) on the same scene,
# from vibrobed's own initial state, at each stiffness k_n; wall time, ratio, and the differences
# in centre of mass, granular temperature and density profile against the seed spread.
# LAMMPS is installed here with apt-get when absent (never a build dependency of vibrobed).
#
# Run from the project root:
#   benches/dem.sh scenarios/vibrated_bed.json --seeds 1,2,3 --duration 150
#   benches/dem.sh scenarios/vibrated_bed.json --kn 1e5 --set floor.gamma=0.8 \
#     --set collisions.tc=0.001
# Options: --set KEY=VALUE (as vibrobed's), --kn LIST (default 1e4,1e5,1e6), --seeds LIST (default:
# the scenario's seed), --duration T (a shorter run.duration), --out DIR (raw results),
# -h or --help (this text, and nothing built or run).
# Runs go one at a time, each on one core: minutes per seed at k_n = 1e6.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
case " $* " in
  *" -h "* | *" --help "*)
    sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
    exit 0
    ;;
esac
if ! command -v lmp >/dev/null; then
  sudo=""
  [ "$(id -u)" = 0 ] || sudo="sudo"
  echo "benches/dem.sh: installing Debian's lammps" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq lammps >/dev/null
fi
cargo build --release -q --manifest-path "$here/../Cargo.toml"
bin="${CARGO_TARGET_DIR:-$here/../target}/release/vibrobed"
exec python3 "$here/dem/side_by_side.py" --vb "$bin" --lmp "$(command -v lmp)" "$@"
