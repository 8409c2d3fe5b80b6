set terminal pngcairo size 1100,750 noenhanced
set output 'docs/accuracy.png'
set logscale xy
set grid
set xlabel 'lavapipe time per megapixel (ms, 2 cores)'
set ylabel 'max relative error, upper hemisphere, sun 3..90 deg'
set title 'skybake: what accuracy costs (single scattering vs converged reference)'
set key top right
plot 'docs/accuracy_front.dat' using 1:2 with lines lw 2 lc rgb '#cc3333' title 'Pareto front', \
     'docs/accuracy_plot.dat' using 1:2:3 with points pt 7 ps 1.2 lc variable title 'cases', \
     'docs/accuracy_plot.dat' using 1:2:4 with labels offset 0.5,0.5 left font ',7' notitle
