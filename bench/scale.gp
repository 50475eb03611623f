# Rays per second and bytes a sphere against sphere count, log x: the CSV of
# bench/scale.sh (data) drawn to the PNG named by `out`. Bytes a sphere from
# 10^5 spheres on: below that they are the allocator's rounding, not the scene's.
set datafile separator ","
set terminal pngcairo size 900,520 font "sans,11"
set output out
set title "ptr: instanced cloud files (bench/make\\_cloud), 640x360, 4 spp, 2 cores"
set logscale x
set xlabel "spheres"
set format x "10^{%L}"
set ylabel "Mrays/s (camera and scattered rays)"
set y2label "bytes a sphere above a one-sphere render"
set yrange [0:*]
set y2range [0:*]
set ytics nomirror
set y2tics
set grid
set key top right
plot data using 1:12 with linespoints pointtype 7 title "Mrays/s" axes x1y1, \
     data using 1:($1 >= 1e5 ? $11 : 1/0) with linespoints pointtype 5 title "bytes a sphere (right)" axes x1y2
