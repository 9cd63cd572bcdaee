#!/usr/bin/env bash
# Photons per CPU second of rtbake's lane kernel on each instruction-set path against the original MCML 1.2.2
# (Wang, Jacques & Zheng 1995) on the same problems, one core each.
#
#   MCML_BIN=/path/to/mcml [MCML_BIN2=/path/to/other-mcml] [LANE_BEFORE=/path/to/lane_paths] [RUNS=3]
#   [PHOTONS=300000] [SAMPLE1=1] bash scripts/bench_mcml.sh
#
# rtbake side: `crates/rtbake-lanes/examples/lane_paths` (the kernel `rtbake transport` runs, one thread, chunks of
# 4096 photons), built with `cargo build --release -p rtbake-lanes --example lane_paths`; each path is forced with
# RTBAKE_LANE_PATH=portable|avx2|avx512 (paths the CPU lacks are skipped) and must print the same checksum.
# MCML side: the .mci input written here (one run, same optical properties, same photon count). Both are timed
# with /usr/bin/time (user + system CPU seconds of the process, so the load of a shared machine does not count);
# RUNS runs each, alternated, medians and the ratio rtbake photons/s over MCML photons/s printed. Without MCML_BIN
# (or if it is not executable) the MCML side is left out and the script says so.
# LANE_BEFORE names another build of the example (e.g. an older commit's, built the same way in a checkout of it, to
# compare a kernel change): it is timed on every path in the same rounds ("before PATH"), its checksums must equal
# the current build's (the line "checksums equal" covers both), and each path's speed-up over it is printed.
#
# Problems (mm, mm^-1; sigma_s = sigma_s'/(1 - g), sigma_s' kept), at g = 0 and g = 0.8:
#   skin:   two layers at one wavelength, air above: epidermis 0.25 mm, eta 1.4, mu_a 1.5, mu_s' 5.0;
#           dermis semi-infinite, eta 1.4, mu_a 0.3, mu_s' 2.0;
#   jensen: a Jensen-like semi-infinite material, air above, eta 1.3, mu_a 0.1, mu_s' 1.0 (reduced albedo 0.91);
# and MCML's own samples/sample1.mci (the cases of examples/bench_transport; SAMPLE1=0 leaves them out):
#   sample1a: van de Hulst's slab, 0.2 mm, eta 1 in air, mu_a 1.0, mu_s 9.0, g 0.75 (10/3 x PHOTONS: 3 interactions
#             per photon);
#   sample1b: semi-infinite, eta 1.5 under air, mu_a 1.0, mu_s 9.0, g 0.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-3}
PHOTONS=${PHOTONS:-300000}
TARGET=${CARGO_TARGET_DIR:-target}
BEFORE=${LANE_BEFORE:-}
if [ -n "$BEFORE" ] && [ ! -x "$BEFORE" ]; then echo "LANE_BEFORE=$BEFORE is not executable" >&2; exit 2; fi
cargo build --release --locked -p rtbake-lanes --example lane_paths >&2
LANE="$TARGET/release/examples/lane_paths"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

MCMLS=()
for b in "${MCML_BIN:-}" "${MCML_BIN2:-}"; do
  if [ -n "$b" ] && [ -x "$b" ]; then MCMLS+=("$b"); fi
done
if [ ${#MCMLS[@]} -eq 0 ]; then
  echo "MCML ABSENT: MCML_BIN is unset or not executable; only rtbake's figures are printed (no ratios)."
  echo "  Build MCML 1.2.2 (github.com/lhvwang/MCML, V1/mcR5unix/mcmlcode: gcc -O3 -o mcml *.c -lm) and set MCML_BIN."
fi

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
cpu() { # command... -> user+sys seconds
  /usr/bin/time -f "%U %S" -o "$WORK/t" "$@" >"$WORK/out" 2>&1
  awk '{print $1 + $2}' "$WORK/t"
}

# mci LAYERS_LINES NLAYERS N ETA_ABOVE ETA_BELOW -> writes $WORK/in.mci (MCML: cm, cm^-1)
write_mci() {
  { echo "1.0"; echo "1"; echo "out.mco A"; echo "$3"; echo "0.01 0.01"; echo "10 100 1"
    echo "$2"; echo "$4"; printf '%b' "$1"; echo "$5"; } > "$WORK/in.mci"
}

# bench_case NAME G PHOTONS ETA_BELOW NLAYERS MCI_LAYER_LINES RTBAKE_LAYER... -> one problem's block of lines
bench_case() {
  local case=$1 g=$2 n=$3 eb=$4 nl=$5 mci=$6
  shift 6
  local layers=("$@")
  write_mci "$mci" "$nl" "$n" 1.0 "$eb"
  declare -A t=()
  sums=""
  rd=""
  for ((r = 0; r < RUNS; r++)); do
    for path in avx512 avx2 portable; do
      out=$(RTBAKE_LANE_PATH=$path "$LANE" 1 1.0 "$eb" "${layers[@]}")
      [[ "$out" == *"path Portable"* && $path != portable ]] && continue   # not supported: detect fell back
      [[ "$out" == *"path Avx2"* && $path == avx512 ]] && continue
      t[$path]+="$(RTBAKE_LANE_PATH=$path cpu "$LANE" "$n" 1.0 "$eb" "${layers[@]}") "
      sums+="$(awk '{print $NF}' "$WORK/out") "
      rd=$(grep -o 'Rd [0-9.]*' "$WORK/out" || true)
      if [ -n "$BEFORE" ]; then
        t[before-$path]+="$(RTBAKE_LANE_PATH=$path cpu "$BEFORE" "$n" 1.0 "$eb" "${layers[@]}") "
        sums+="$(awk '{print $NF}' "$WORK/out") "
      fi
    done
    for i in "${!MCMLS[@]}"; do
      t[mcml$i]+="$(cd "$WORK" && cpu "${MCMLS[$i]}" in.mci) "
    done
  done
  nsum=$(echo $sums | tr ' ' '\n' | sort -u | wc -l)
  echo "== $case, g $g, $n photons, $RUNS runs, rtbake $rd, checksums equal across paths and runs: $([ "$nsum" = 1 ] && echo yes || echo NO)"
  for i in "${!MCMLS[@]}"; do
    [ -f "$WORK/out.mco" ] && echo "   MCML ${MCMLS[$i]}: Rd $(grep -m1 'Diffuse reflectance' "$WORK/out.mco" | awk '{print $1}')"
  done
  for key in avx512 avx2 portable before-avx512 before-avx2 before-portable $(for i in "${!MCMLS[@]}"; do echo mcml$i; done); do
    [ -n "${t[$key]:-}" ] || continue
    m=$(echo ${t[$key]} | tr ' ' '\n' | median)
    rate=$(awk -v n="$n" -v m="$m" 'BEGIN {printf "%.3f", n / m / 1e6}')
    name=$key; [[ $key == mcml* ]] && name="MCML ${MCMLS[${key#mcml}]}"
    line=$(printf '   %-28s median %6.3f CPU-s (runs: %s) %s M photons/s' "$name" "$m" "$(echo ${t[$key]})" "$rate")
    if [[ $key != mcml* ]]; then
      if [[ $key != before-* && -n "${t[before-$key]:-}" ]]; then
        mb=$(echo ${t[before-$key]} | tr ' ' '\n' | median)
        line+=$(awk -v a="$m" -v b="$mb" 'BEGIN {printf "; %.2fx before", b / a}')
      fi
      for i in "${!MCMLS[@]}"; do
        mm=$(echo ${t[mcml$i]} | tr ' ' '\n' | median)
        line+=$(awk -v a="$m" -v b="$mm" -v n="$(basename "${MCMLS[$i]}")" 'BEGIN {printf "; %.2fx %s", b / a, n}')
      done
    fi
    echo "$line"
  done
  unset t
}

for g in 0 0.8; do
  s=$(awk -v g="$g" 'BEGIN {print 1 / (1 - g)}')
  # rtbake layers (mm): thickness,eta,mu_a,mu_s,g; MCML layers (cm): n mua mus g d
  skin_r=("0.25,1.4,1.5,$(awk -v s="$s" 'BEGIN{print 5.0*s}'),$g" "inf,1.4,0.3,$(awk -v s="$s" 'BEGIN{print 2.0*s}'),$g")
  skin_m="1.4 15 $(awk -v s="$s" 'BEGIN{print 50*s}') $g 0.025\n1.4 3 $(awk -v s="$s" 'BEGIN{print 20*s}') $g 1E+8\n"
  jen_r=("inf,1.3,0.1,$(awk -v s="$s" 'BEGIN{print 1.0*s}'),$g")
  jen_m="1.3 1 $(awk -v s="$s" 'BEGIN{print 10*s}') $g 1E+8\n"
  bench_case skin "$g" "$PHOTONS" 1.4 2 "$skin_m" "${skin_r[@]}"
  bench_case jensen "$g" "$PHOTONS" 1.3 1 "$jen_m" "${jen_r[@]}"
done
if [ "${SAMPLE1:-1}" = 1 ]; then
  bench_case "sample1a van de Hulst slab" 0.75 $((PHOTONS * 10 / 3)) 1.0 1 "1.0 10 90 0.75 0.02\n" "0.2,1.0,1.0,9.0,0.75"
  bench_case "sample1b semi-infinite" 0 "$PHOTONS" 1.5 1 "1.5 10 90 0 1E+8\n" "inf,1.5,1.0,9.0,0"
fi
