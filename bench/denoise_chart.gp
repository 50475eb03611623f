# Relative MSE against seconds (render, plus the denoiser for the denoised
# curves), log-log, one panel per scene: the raw render against its
# denoised image at each quality. Reads the CSV of `accuracy denoise`;
# writes the PNG named by `out`.
set datafile separator ","
set terminal pngcairo size 1200,520 font "sans,11"
set output out
set multiplot layout 1,2 title "ptr --denoise: relative MSE against a 16,384-spp reference, 1 to 1024 samples per pixel (2 shared cores)"
set logscale xy
set xlabel "seconds (render + denoise)"
set ylabel "relative MSE"
set grid
set key bottom left
methods = "raw fast balanced high"
do for [scene in "final 1tii"] {
    set title scene eq "final" ? "final.gltf (486 spheres, 160x90)" : "1tii.pdb (5469 atoms, 96x72)"
    # Each curve's rows apart: the CSV interleaves the methods at each spp.
    plot for [m in methods] sprintf("< grep '^%s,%s,' %s", scene, m, data) using 4:6 \
        with linespoints pointtype 7 pointsize 0.8 title m
}
unset multiplot
