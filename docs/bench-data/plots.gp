set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/solve_time.png'
set title 'Solve time per grasp, median (SDF build not included)'
set ylabel 'microseconds (log scale)'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set logscale y
plot for [i=2:5] 'solve_time.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/check_us.png'
set title 'check_us median per method and mesh'
set ylabel 'check_us median'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'check_us.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/exact_samples_mean.png'
set title 'exact_samples_mean per method and mesh'
set ylabel 'exact_samples_mean'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'exact_samples_mean.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/tip_residual_mm.png'
set title 'tip_residual_mm median per method and mesh'
set ylabel 'tip_residual_mm median'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'tip_residual_mm.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/contact_residual_mm.png'
set title 'contact_residual_mm median per method and mesh'
set ylabel 'contact_residual_mm median'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'contact_residual_mm.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/pass_through.png'
set title 'pass_through per method and mesh'
set ylabel 'pass_through'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'pass_through.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/penetration_mm.png'
set title 'penetration_mm p99 per method and mesh'
set ylabel 'penetration_mm p99'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'penetration_mm.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/early_stops.png'
set title 'early_stops per method and mesh'
set ylabel 'early_stops'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'early_stops.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set output '../img/bench/contacts_mean.png'
set title 'contacts_mean per method and mesh'
set ylabel 'contacts_mean'
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set key outside right top
set xtics rotate by -25
set yrange [0:*]
plot for [i=2:5] 'contacts_mean.dat' using i:xtic(1) title columnheader(i)
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set xrange [3291.43:999760]
set output '../img/bench/sdf_build_triangles.png'
set title 'Grab-box SDF build time against triangle count (16^3 nodes)'
set xlabel 'triangles (log scale)'
set ylabel 'build time per grab (ms)'
set logscale y
set logscale x
set format x '%.0s%c'
set key left top
set grid xtics lc rgb '#dddddd'
plot 'sdf_build_triangles.dat' using 2:3 with linespoints lw 2 pt 7 title 'CPU build', 'sdf_build_triangles.dat' using 2:4 with linespoints lw 2 pt 7 title 'Vulkan build', 'sdf_build_triangles.dat' using 2:5 with linespoints lw 2 pt 7 title 'CPU build + sampling', 'sdf_build_triangles.dat' using 2:6 with linespoints lw 2 pt 7 title 'Vulkan build + sampling', 'sdf_build_triangles.dat' using 2:(int($0) % 2 == 0 ? $3 : NaN):1 with labels offset 0,1 font 'sans,8' notitle, 'sdf_build_triangles.dat' using 2:(int($0) % 2 == 1 ? $3 : NaN):1 with labels offset 0,-1 font 'sans,8' notitle
reset
set terminal pngcairo size 1000,520 noenhanced font 'sans,10'
set datafile missing 'NaN'
set grid ytics lc rgb '#dddddd'
set border 3
set tics nomirror
set xtics (16, 32, 64)
set xrange [11.4286:89.6]
set output '../img/bench/sdf_build_resolution.png'
set title 'Grab-box SDF build time against resolution (torus-99856, 99,856 triangles)'
set xlabel 'grid nodes per axis (log scale)'
set ylabel 'build time per grab (ms)'
set logscale y
set logscale x
set format x '%.0s%c'
set key left top
set grid xtics lc rgb '#dddddd'
plot 'sdf_build_resolution.dat' using 2:3 with linespoints lw 2 pt 7 title 'CPU build', 'sdf_build_resolution.dat' using 2:4 with linespoints lw 2 pt 7 title 'Vulkan build', 'sdf_build_resolution.dat' using 2:5 with linespoints lw 2 pt 7 title 'CPU build + sampling', 'sdf_build_resolution.dat' using 2:6 with linespoints lw 2 pt 7 title 'Vulkan build + sampling'
