#!/bin/sh
# Runs the Slurm recipe of docs/distributed.md against a single-node Slurm
# started here on localhost: installs Debian's slurm-wlm and munge, starts
# munged, slurmctld and slurmd by hand (no systemd), submits the job array and
# the merge job exactly as the documentation writes them, and checks that the
# merged image equals a single render to within float rounding.
#
# It installs packages and starts daemons as root: run it on a machine of its
# own (CI may, when time allows), not in the normal suite.
# Usage: slurm_recipe.sh PTR_BUILD_BIN_DIR SOURCE_DIR
set -eu
bin=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
[ "$(id -u)" -eq 0 ] || { echo "slurm_recipe.sh: run as root" >&2; exit 2; }
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        slurm-wlm munge >/dev/null
fi

work=$(mktemp -d /tmp/ptr-slurm-XXXXXX)
chmod 755 "$work"
pids=""
cleanup() {
    for p in $pids; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
    sleep 1
    rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# munge: a key of our own, the daemon as the munge user with its own socket.
mkdir -p "$work/munge" && chown munge: "$work/munge" && chmod 700 "$work/munge"
dd if=/dev/urandom bs=1 count=1024 of="$work/munge/munge.key" 2>/dev/null
chown munge: "$work/munge/munge.key" && chmod 400 "$work/munge/munge.key"
runuser -u munge -- munged --key-file="$work/munge/munge.key" --socket="$work/munge/socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/seed" --force
pids="$(cat "$work/munge/munged.pid")"

cpus=$(nproc)
mkdir -p "$work/spool/ctld" "$work/spool/d"
cat >"$work/slurm.conf" <<CONF
ClusterName=ptr
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmctldPort=16817
SlurmdPort=16818
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
SlurmdSpoolDir=$work/spool/d
StateSaveLocation=$work/spool/ctld
JobCompType=jobcomp/none
NodeName=localhost CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -D -f "$SLURM_CONF" >"$work/slurmctld.out" 2>&1 & pids="$pids $!"
slurmd -D -f "$SLURM_CONF" >"$work/slurmd.out" 2>&1 & pids="$pids $!"
i=0
until timeout 5 sinfo -h -o %T 2>/dev/null | grep -q idle; do
    i=$((i + 1)); [ $i -gt 60 ] && { echo "slurm did not come up" >&2; cat "$work"/*.log >&2; exit 1; }
    sleep 1
done

# The recipe, as docs/distributed.md writes it.
cd "$work"
export PATH="$bin:$PATH"
cp "$src/scenes/final.gltf" scene.gltf
SCENE=scene.gltf OUT=merged.exr PARTS=4 SPP=16
awk '$0 == "# render-part.sbatch" { on = 1; next } on && /^```/ { exit } on { print }' \
    "$src/docs/distributed.md" >render-part.sbatch
submit=$(awk 'prev && /^```sh$/ { on = 1; next } on && /^```/ { exit } on { print }
              /render-part.sbatch/ && /^```/ { prev = 0 } /^# render-part.sbatch/ { prev = 1 }' \
    "$src/docs/distributed.md")
[ -s render-part.sbatch ] && [ -n "$submit" ] || { echo "recipe not found in the docs" >&2; exit 1; }
export SCENE SPP PARTS OUT
sh -eu -c "$submit"

i=0
until [ -s merged.exr ] && ! timeout 5 squeue -h | grep -q .; do
    i=$((i + 1)); [ $i -gt 300 ] && { echo "the jobs did not finish" >&2; squeue >&2; exit 1; }
    sleep 1
done
ptr scene.gltf -o single.exr --samples "$SPP" --quiet
oiiotool single.exr merged.exr --diff --fail 1e-5
echo "1 passed, 0 failed"
