#!/usr/bin/env bash
# The reliability trial, repeatable: concurrent bakes and verifies of one directory, and a kill at every step of the
# bake's stage-and-swap; prints the counts of corrupt outcomes (must be 0).
#   scripts/trial_reliability.sh [RTBAKE] [ROUNDS]     (defaults: target/debug/rtbake, 24)
#   TRIAL_A / TRIAL_B name the two assets (defaults transmittance, smaa-search: a few ms each; burley-profiles and
#   skin-color-lut take 0.2-0.3 s, so their bakes overlap for longer)
set -uo pipefail
R=${1:-target/debug/rtbake}
N=${2:-24}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
A=${TRIAL_A:-transmittance}; B=${TRIAL_B:-smaa-search}
bad=0; vbad=0
for i in $(seq 1 "$N"); do
  d=$T/c$i
  "$R" bake -q --out "$d" $A & p1=$!
  "$R" bake -q --out "$d" $B & p2=$!
  "$R" verify -q --dir "$d" >/dev/null 2>&1 & p3=$!   # may find no bake yet (exit 2) but never a torn one (exit 1)
  wait $p1 $p2; wait $p3; vrc=$?
  if [ "$vrc" -eq 1 ]; then vbad=$((vbad + 1)); echo "round $i: concurrent verify saw a corrupt state"; fi
  if ! "$R" verify -q --dir "$d" >/dev/null 2>&1 || ! grep -q "\"$A\"" "$d/manifest.json" || ! grep -q "\"$B\"" "$d/manifest.json"; then
    bad=$((bad + 1)); echo "round $i: corrupt or lost update"
  fi
done
echo "concurrent bake+bake+verify: $N rounds, $bad corrupt or lost updates, $vbad concurrent verifies that saw a corrupt state"
kbad=0; kn=0
for step in locked probe staged before-swap after-swap; do
  for round in 1 2 3 4 5; do
    d=$T/k-$step-$round
    "$R" bake -q --out "$d" $A >/dev/null 2>&1
    RTBAKE_FAULT_INJECT="kill@$step" "$R" bake -q --out "$d" $B >/dev/null 2>&1
    kn=$((kn + 1))
    # The directory is the old state (A only) or the new one (A and B); verify recovers leftovers under the lock.
    if ! "$R" verify -q --dir "$d" >/dev/null 2>&1 || ! grep -q "\"$A\"" "$d/manifest.json"; then
      kbad=$((kbad + 1)); echo "kill@$step round $round: broken state"
    fi
  done
done
echo "kill at every swap step (locked, probe, staged, before-swap, after-swap) x 5: $kn kills, $kbad broken states"
[ "$bad" -eq 0 ] && [ "$vbad" -eq 0 ] && [ "$kbad" -eq 0 ]
