# Mrays/s against sphere count, log-log: brute force and the tree, C and the
# fastest assembly. Reads the CSV of bench/bvh; writes the PNG named by `out`.
set datafile separator ","
set terminal pngcairo size 900,520 font "sans,11"
set output out
set title "ptr: cloud scenes (a ground, spheres at 8% volume fraction), 400x225, 2 spp, 2 cores (AVX2)"
set logscale xy
set xlabel "spheres"
set ylabel "Mrays/s (camera and scattered rays)"
set format x "10^{%L}"
set grid
set key bottom left
plot data using 1:4 with linespoints pointtype 7 title "brute force, C", \
     data using 1:5 with linespoints pointtype 7 title "brute force, assembly", \
     data using 1:6 with linespoints pointtype 5 title "tree, C traversal", \
     data using 1:7 with linespoints pointtype 5 title "tree, assembly traversal (table's)"
