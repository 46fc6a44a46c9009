#!/usr/bin/env bash
# Campaign shards as a Slurm job array on a one-node cluster this test starts (Debian's
# slurm-wlm, tests/support/slurm_one_node.sh): task K runs --shard K/N, then
# `plcfi merge` must give the journal and the traces of the single run. Skipped (77, with
# the reason) only where the cluster cannot start.
# usage: slurm_shards.sh PLCFI SOURCE_DIR
set -euo pipefail
plcfi=$1
src=$2
work=$(mktemp -d /tmp/plcfi_slurm_XXXXXX)  # short: slurmd's socket paths live under it
trap 'rm -rf "$work"' EXIT
command -v sbatch >/dev/null || { echo "SKIP: Slurm (sbatch) is not installed"; exit 77; }
campaign=$src/faults/campaigns/stamping/campaign.yaml

s=0
"$plcfi" campaign "$campaign" --out "$work/single" --quiet > /dev/null || s=$?
[[ $s -le 1 ]] || { echo "FAIL: the single run exited $s"; exit 1; }

# The job script, as a user writes it for sbatch --array=0-(N-1).
cat > "$work/shard.sbatch" <<JOB
#!/usr/bin/env bash
#SBATCH --job-name=plcfi-shards
exec "$plcfi" campaign "$campaign" --shard \${SLURM_ARRAY_TASK_ID}/\${SLURM_ARRAY_TASK_COUNT} \\
  --out "$work/shard\${SLURM_ARRAY_TASK_ID}" --quiet
JOB
chmod +x "$work/shard.sbatch"
s=0
SLURM_HARNESS_TIMEOUT=${SLURM_HARNESS_TIMEOUT:-600} "$src/tests/support/slurm_one_node.sh" "$work" 3 "$work/shard.sbatch" || s=$?
[[ $s -eq 77 ]] && exit 77  # the harness printed SKIP: and the reason
[[ $s -eq 0 ]] || { echo "FAIL: the Slurm array job failed ($s)"; exit 1; }

s=0
"$plcfi" merge --out "$work/merged" "$work"/shard*/shard-*-of-3.jsonl > "$work/merge.txt" || s=$?
[[ $s -le 1 ]] || { cat "$work/merge.txt"; echo "FAIL: merge exited $s"; exit 1; }
cmp "$work/single/results.jsonl" "$work/merged/results.jsonl" || { echo "FAIL: the merged journal differs"; exit 1; }
for f in "$work"/single/*.vcd; do
  cmp -s "$f" "$work/merged/$(basename "$f")" || { echo "FAIL: trace $(basename "$f") differs"; exit 1; }
done
echo "ok: 3 Slurm array tasks, merged journal = single run ($(($(wc -l < "$work/single/results.jsonl") - 1)) verdicts)"
