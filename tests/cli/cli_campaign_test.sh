#!/usr/bin/env bash
# The command line's attack campaign (scripts/cli_campaign.py) at a small fixed budget: --out
# values, scalpel CSVs, scene files, extreme numbers, signals at random times and concurrent
# runs, each inside a throw-away home of the user's files. Fails on any defect it counts:
# a user's file touched, an injected command run, an orphan, a staging folder left, an exit
# code that does not match the outcome, a hang or a non-model input growing past 512 MiB.
set -euo pipefail
conform="$1"
root="$2"
runs="${CONFORM_CAMPAIGN_RUNS:-240}"
rss_mb=512
limit=30
if [[ -n "${CONFORM_SANITIZED:-}" ]]; then
  runs=60       # the sanitized binary is several times slower
  rss_mb=4096   # and ASan's shadow memory and quarantine count in its resident size
  limit=120     # a whole membrane-patch run takes 7 s unsanitized
fi
exec /usr/bin/python3 "$root/scripts/cli_campaign.py" --conform "$conform" --runs "$runs" \
  --seed 1 --jobs 2 --limit "$limit" --max-rss-mb "$rss_mb"
