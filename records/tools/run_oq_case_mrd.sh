#!/bin/sh
# Run the OpenQuake engine on its QA case postproc/case_mrd as shipped in
# records/hazard/openquake_postproc_case_mrd/input, in a temporary directory, and write
# what records/hazard/openquake_postproc_case_mrd holds (the mrd extracts, the curves,
# the Mag_Dist disaggregation) to OUT_DIR, stating the engine's wall time of each step.
#
#   records/tools/run_oq_case_mrd.sh OQ_PYTHON [OUT_DIR]
#
# OQ_PYTHON: the Python of an environment where `pip install openquake-engine` went in
# (the engine's pins may clash with the project's: give it an environment of its own).
# One process (OQ_DISTRIBUTE=no); the datastores stay in the temporary directory (the
# engine keeps its list of calculations in its own database, ~/oqdata by default).  The numbers match the shipped files; the files' bytes do not
# (each holds its run's date and checksum).
set -eu
OQ_PYTHON=${1:?usage: run_oq_case_mrd.sh OQ_PYTHON [OUT_DIR]}
# absolute, its symlinks kept (a venv's python is one): the steps run in a temporary directory
OQ_PYTHON=$(realpath -s -- "$OQ_PYTHON")
OUT=$(realpath -m "${2:-results/oq_case_mrd}")
HERE=$(cd "$(dirname "$0")/../.." && pwd)
if ! "$OQ_PYTHON" -c "import openquake.engine" 2>/dev/null; then
    echo "no OpenQuake engine in $OQ_PYTHON: python3 -m venv oq-venv && oq-venv/bin/pip install openquake-engine" >&2
    exit 2
fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cp -r "$HERE/records/hazard/openquake_postproc_case_mrd/input" "$WORK/input"
export OQ_DATADIR="$WORK/oqdata" OQ_DISTRIBUTE=no
OQ="$OQ_PYTHON -m openquake.commands"
mkdir -p "$OUT"
cd "$WORK/input"
calc_id() { grep -o "calc_[0-9]*\.hdf5" "$1" | tail -1 | sed 's/calc_\([0-9]*\)\.hdf5/\1/'; }
for job in job job_pga_pgv job_disagg; do
    start=$(date +%s.%N)
    $OQ engine --run $job.ini -e csv -p export_dir="$WORK/out_$job" >"$WORK/$job.log" 2>&1
    end=$(date +%s.%N)
    echo "$job.ini: engine wall time $(echo "$end - $start" | bc) s"
done
qa=$(calc_id "$WORK/job.log"); pgv=$(calc_id "$WORK/job_pga_pgv.log")
dis=$(calc_id "$WORK/job_disagg.log")
rlz=$($OQ engine --lo "$dis" 2>&1 | awk '/Per Realization/ {print $1}')
$OQ engine --eo "$rlz" "$WORK/out_job_disagg" >/dev/null 2>&1
start=$(date +%s.%N)
"$OQ_PYTHON" "$HERE/records/tools/oq_mrd_extract.py" "$OQ_DATADIR/calc_$pgv.hdf5" \
    "$OUT/mrd_pga_pgv.hdf5"
end=$(date +%s.%N)
echo "compute_mrd (PGA, PGV): wall time $(echo "$end - $start" | bc) s"
"$OQ_PYTHON" "$HERE/records/tools/oq_mrd_extract.py" "$OQ_DATADIR/calc_$qa.hdf5" \
    "$OUT/mrd_pga_sa0.05.hdf5"
mkdir -p "$OUT/disaggregation"
cp "$WORK"/out_job_pga_pgv/hazard_curve-*.csv "$WORK"/out_job_pga_pgv/realizations_*.csv "$OUT/"
cp "$WORK"/out_job_disagg/Mag_Dist-*.csv "$OUT/disaggregation/"
echo "written to $OUT"
