# Error against render time, log-log, one line per estimator, one panel per
# scene. Reads the CSV of `accuracy estimators`; writes the PNG named by `out`.
set datafile separator ","
set terminal pngcairo size 1200,520 font "sans,11"
set output out
set multiplot layout 1,2 title "ptr: RMSE against a 4096-spp reference, 1 to 256 samples per pixel, mean of 4 seeds (2 cores)"
set logscale xy
set xlabel "render time (s)"
set ylabel "RMSE (scene-linear)"
set grid
set key bottom left
methods = "independent sobol independent+direct sobol+direct adaptive"
do for [scene in "final lamps"] {
    set title scene eq "final" ? "final.gltf (486 spheres, gradient sky, 200x112)" : "lamps.gltf (24 small emitters, black sky, 200x112)"
    plot for [m in methods] data using \
        (strcol(1) eq scene && strcol(2) eq m ? $4 : NaN):(strcol(1) eq scene && strcol(2) eq m ? $5 : NaN) \
        with linespoints pointtype 7 pointsize 0.8 title m
}
unset multiplot
