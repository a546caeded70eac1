#!/usr/bin/env bash
# Regenerates every figure in docs/figures/ in one command, at the paper's sizes except Figs. 13-14:
#   bash scripts/make-figures.sh            # JOBS=1 bash scripts/make-figures.sh runs one simulation at a time
#   FORMAT=pdf FIGURES=out/vector bash scripts/make-figures.sh   # vector figures (pdf or svg) into another folder
#   FIG10=0 leaves out the two extra grids of Fig. 10 (the longest runs)
# Builds the release program if needed and runs, two at a time by default (times on one idle core):
#   oblate_shear at b/a = 0.9 (G = 0.1, 0.2) and b/a = 0.5 (G = 0.2)              (§4.2.2, Figs. 8-9; 10-30 min each)
#   oblate_shear, b/a = 0.9, G = 0.2 at 64^3 with 4,098 nodes and at 96^3          (§4.2.2, Fig. 10; 10-40 min each)
#   oscillating_membrane at mu = 0.01 with dt = dx and 4 dx, at mu = 0.1 with dt = dx  (§4.1, Figs. 2-5; 0.5-2 min)
#   oscillating_membrane with explicit Euler and with JFNK at dt = 4 dx, a frame per step     (§4.1, Fig. 6)
#   capsule_shear at G = 0.0125, 0.05, 0.1 and 0.2                               (§4.2.1, Fig. 7; 1-2 min each)
#   bending_shear at G = 0.05, kappa_B_hat = 0, 0.01, 0.025, 0.0375 to k t = 4   (§4.2.3, Fig. 11a)
#   bending_shear at G = 0.2, kappa_B_hat = 0, 0.04, 0.1, 0.15 to k t = 4       (§4.2.3, Fig. 11b)
#   rbc_channel, 32 cells to t = 0.05 s                                          (§4.4, Fig. 15; about 2 min)
#   rbc_stretch_quick at mu0 = 7.3, 10 uN/m, forces 0, 38.9, 110, 194 pN, looser steady state  (§4.3, Figs. 13-14;
#     the paper's 128^3 grid takes hours per sweep), and the area-conserving cell on 64^3 (Fig. 13, about 30 min)
#   capsule_pair_quick and capsule_pair, two capsules crossing in shear (Lac, Morel & Barthes-Biesel 2007)
#   suspension_shear at hematocrits 0.1, 0.2, 0.3, 0.4 (relative viscosity; 5-15 min each, stopped where a
#     membrane folds)
# into out/figures/, then plots with Debian's matplotlib (/usr/bin/python3). Each plot script prints its key numbers.
set -euo pipefail
cd "$(dirname "$0")/.."
python=/usr/bin/python3
runs=out/figures
figs=${FIGURES:-docs/figures}
ext=${FORMAT:-png}
case $ext in png | pdf | svg) ;; *) echo "make-figures: FORMAT=$ext: expected png, pdf or svg"; exit 2 ;; esac
jobs_max=${JOBS:-2}
# Simulations side by side take one thread each unless OMP_NUM_THREADS says otherwise.
(( jobs_max > 1 )) && export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
mkdir -p "$runs" "$figs"

[[ -f build/release/CMakeCache.txt ]] || cmake --preset release >/dev/null
cmake --build build/release -j2 --target immerse >/dev/null
immerse=build/release/immerse

# run SCENARIO OUTDIR [--set key=value ...]: one simulation, its log in OUTDIR.log. With MAY_STOP=1 a run that
# the numerics stop (exit status 3, e.g. an inverted element) keeps its output and its plot shows where it ended.
run() {
  local scenario=$1 out=$2
  shift 2
  rm -rf "$out" "$out.failed"
  local status=0
  "$immerse" run "scenarios/$scenario.toml" --out "$out" "$@" > "$out.log" 2>&1 || status=$?
  if (( status == 0 )); then
    echo "== $scenario -> $out $*: $(grep -m1 '^membrane\[0\]' "$out.log" || tail -1 "$out.log")"
  elif (( status == 3 )) && [[ ${MAY_STOP:-0} == 1 ]]; then  # stopped by the numerics: plotted up to there
    echo "== $scenario -> $out $*: STOPPED EARLY, plotted up to there: $(grep -m1 'run stopped' "$out.log")"
  else
    echo "== $scenario -> $out $*: immerse run failed, see $out.log:"; tail -3 "$out.log"; touch "$out.failed"
  fi
}

start() { # start SCENARIO OUTDIR [...]: run in the background, at most $jobs_max at a time
  while (( $(jobs -rp | wc -l) >= jobs_max )); do wait -n; done
  run "$@" &
}

dx=0.015625  # the oscillating membrane's grid spacing, 1/64
# The longest runs first, so that two at a time finish together. Fig. 8's G = 0.2 run is also Fig. 10's 64^3 grid.
for case in 0.9:0.2 0.9:0.1 0.5:0.2; do
  IFS=: read -r ba G <<< "$case"
  MAY_STOP=1 start oblate_shear "$runs/oblate_ba${ba}_G$G" --set scenario.aspect_ratio=$ba --set scenario.G=$G \
    --set output.fields_every=0
done
# Fig. 10: the paper's refinement study, the coarser membrane on 64^3 and the finer grid 96^3.
if [[ ${FIG10:-1} == 1 ]]; then
  start oblate_shear "$runs/refine_64_octahedral" --set scenario.G=0.2 --set 'membrane[0].mesh.family="octahedral"' \
    --set output.fields_every=0
  start oblate_shear "$runs/refine_96_icosahedral" --set scenario.G=0.2 --set grid.nx=96 --set grid.ny=96 \
    --set grid.nz=96 --set output.fields_every=0
fi
# At dt = dx a frame every 64 steps is one per unit of time (Fig. 3 draws t = 0, 1, 2, 10).
start oscillating_membrane "$runs/osc_mu0.01" --set fluid.mu=0.01 --set time.dt=$dx --set output.fields_every=64 \
  --set output.fluid_fields=false
start oscillating_membrane "$runs/osc_mu0.01_4dx" --set fluid.mu=0.01 --set output.fluid_fields=false
start oscillating_membrane "$runs/osc_mu0.1" --set fluid.mu=0.1 --set time.dt=$dx --set output.fields_every=64 \
  --set output.fluid_fields=false
# Fig. 6: explicit Euler and JFNK at dt = 4 dx, a frame every step; Euler goes unstable within a few steps.
MAY_STOP=1 start oscillating_membrane "$runs/osc_euler" --set fluid.mu=0.01 --set time.scheme=euler \
  --set time.end=1.5 --set output.fields_every=1 --set output.fluid_fields=false
start oscillating_membrane "$runs/osc_jfnk" --set fluid.mu=0.01 --set time.end=1.5 --set output.fields_every=1 \
  --set output.fluid_fields=false
for G in 0.0125 0.05 0.1 0.2; do
  start capsule_shear "$runs/shear_G$G" --set scenario.G=$G --set output.fields_every=0
done
# The plateau is reached by k t = 3: k t = 4 (200 steps) instead of the scenario's 10 saves time.
for kappa in 0 0.01 0.025 0.0375; do
  start bending_shear "$runs/bending_G0.05_kB$kappa" --set scenario.G=0.05 --set scenario.kappa_B_hat=$kappa \
    --set scenario.kt_end=4 --set output.fields_every=0
done
for kappa in 0 0.04 0.1 0.15; do
  start bending_shear "$runs/bending_G0.2_kB$kappa" --set scenario.G=0.2 --set scenario.kappa_B_hat=$kappa \
    --set scenario.kt_end=4 --set output.fields_every=0
done
# On the quick grid the cell creeps for many relaxation times under each force: the figure runs call it steady at
# 0.5 % change per relaxation time (instead of 0.01 %) and move on after at most 8 relaxation times, to stay within
# minutes. Fig. 14 draws the cell at the end of each force: frames at every step (membranes only) for mu0 = 7.3.
for mu0 in 7.3 10; do
  frames=()
  [[ $mu0 == 7.3 ]] && frames=(--set output.fields_every=1 --set output.fluid_fields=false)
  start rbc_stretch_quick "$runs/rbc_mu0_$mu0" --set scenario.mu0=${mu0}e-6 \
    --set "scenario.forces_pN=[0, 38.9, 110, 194]" --set scenario.steady_tol=5e-3 \
    --set scenario.max_relaxation_times=8 "${frames[@]}"
done
# Fig. 13 also shows the area-conserving red cell (Yeoh law plus a global area constraint of 1 mN/m) on a 64^3 grid
# with 4,098 nodes at the forces of Mills et al. (2004), each to the default steady state (about 30 min on one core).
start rbc_stretch_quick "$runs/rbc_area_64" --set "scenario.forces_pN=[0, 15.987, 47.245, 108.949, 192.688]" \
  --set scenario.steady_tol=1e-4 --set scenario.max_relaxation_times=200 --set time.end=5 \
  --set 'membrane[0].area_modulus=1e-3' --set grid.nx=64 --set grid.ny=64 --set grid.nz=64 \
  --set 'membrane[0].mesh.level=4' --set output.fields_every=0
# Two capsules crossing in shear (Lac et al. 2007): trajectory and shapes at both sizes.
start capsule_pair_quick "$runs/pair"
start capsule_pair "$runs/pair_full" --set output.fields_every=0
# Fig. 15: the 32 cells of the channel at t = 0 and t = 0.05 s.
start rbc_channel "$runs/channel" --set output.fluid_fields=false
# A red cell in shear at viscosity ratio 1 (tank-treading) and 5 (tumbling), quick and finer size.
for lambda in 1 5; do
  start rbc_shear_quick "$runs/rbc_shear_l$lambda" --set "membrane[0].viscosity_ratio=$lambda"
  start rbc_shear "$runs/rbc_shear_full_l$lambda" --set "membrane[0].viscosity_ratio=$lambda"
done
# Red cells between sliding walls at four hematocrits: the relative viscosity curve. The denser runs stop where an
# element of a cell folds (exit 3; docs/scenarios/suspension-shear.md) and are plotted up to there.
for H in 0.4 0.3 0.2 0.1; do
  MAY_STOP=1 start suspension_shear "$runs/suspension_H$H" --set packing.volume_fraction=$H
done
wait
if compgen -G "$runs/*.failed" >/dev/null; then echo "some runs failed: no figures written"; exit 1; fi

$python scripts/plot_iterations.py "$runs/osc_mu0.01" "$runs/osc_mu0.01_4dx" -o "$figs/fig2_iterations.$ext"
$python scripts/plot_shapes.py "$runs/osc_mu0.01" --frames 0,1,2,10 -o "$figs/fig3_shapes.$ext"
$python scripts/plot_semi_axes.py "$runs/osc_mu0.01" -o "$figs/fig4_semi_axes_mu0.01.$ext"
$python scripts/plot_semi_axes.py "$runs/osc_mu0.1" -o "$figs/fig5_semi_axes_mu0.1.$ext"
$python scripts/plot_taylor.py "$runs"/shear_G{0.0125,0.05,0.1,0.2} -o "$figs/fig7_taylor.$ext"
$python scripts/plot_taylor.py "$runs"/oblate_ba0.9_G0.1 "$runs"/oblate_ba0.9_G0.2 -o "$figs/fig8_oblate_ba0.9.$ext"
$python scripts/plot_taylor.py "$runs"/oblate_ba0.5_G0.2 -o "$figs/fig9_oblate_ba0.5.$ext"
if [[ ${FIG10:-1} == 1 ]]; then
  $python scripts/plot_taylor.py "$runs"/refine_64_octahedral "$runs"/oblate_ba0.9_G0.2 "$runs"/refine_96_icosahedral \
    --title "Oblate capsule, b/a = 0.9, G = 0.2: grid refinement" -o "$figs/fig10_refinement.$ext"
fi
$python scripts/plot_taylor.py "$runs"/bending_G0.05_kB{0,0.01,0.025,0.0375} -o "$figs/fig11_bending_G0.05.$ext"
$python scripts/plot_taylor.py "$runs"/bending_G0.2_kB{0,0.04,0.1,0.15} -o "$figs/fig11b_bending_G0.2.$ext"
$python scripts/plot_shapes.py "$runs/osc_euler" --frames 0,3,6,-1 -o "$figs/fig6_explicit_shapes.$ext"
$python scripts/plot_shapes.py "$runs/osc_jfnk" --frames 0,3,6,-1 -o "$figs/fig6_implicit_shapes.$ext"
$python scripts/plot_stretch.py "$runs"/rbc_mu0_7.3 "$runs"/rbc_mu0_10 "$runs"/rbc_area_64 -o "$figs/fig13_stretch.$ext"
$python scripts/plot_shapes.py "$runs"/rbc_mu0_7.3 --forces 0,38.9,110,194 --view 35,-60 -o "$figs/fig14_rbc_shapes.$ext"
$python scripts/plot_shapes.py "$runs/channel" --frames 0,-1 --box --side x --columns 1 -o "$figs/fig15_channel.$ext"
$python scripts/plot_pair.py "$runs/pair" "$runs/pair_full" -o "$figs/capsule_pair.$ext"
$python scripts/plot_shapes.py "$runs/pair" --frames 0,5,6,9 --side y --columns 2 \
  --title "Two capsules crossing in shear, G = 0.05, seen along y" -o "$figs/capsule_pair_shapes.$ext"
$python scripts/plot_rbc_shear.py "$runs"/rbc_shear_l{1,5} "$runs"/rbc_shear_full_l{1,5} --shapes 0,4,8,12,16,20 \
  -o "$figs/rbc_shear.$ext"
$python scripts/plot_suspension_shear.py "$runs"/suspension_H{0.1,0.2,0.3,0.4} --from-kt 1 \
  -o "$figs/suspension_shear.$ext"
