# The tear-opening wound's largest physical opening against the attachment stiffness k and
# Young's modulus E, beside the foundation limit of a slit much longer than the decay length:
#   w = 2 sigma l / E'',  l = sqrt(E'' t / k),  E'' = E / (1 - nu^2).
# Usage: gnuplot -e "csv='DIR/sweep.csv'; out='tear_opening_foundation.png'" tear_opening_foundation.gp
# with DIR from: conform sweep tear-opening --grid material.attachment_stiffness=1e5,2e5,4e5,8e5,1.6e6
#                  --grid material.youngs_modulus=2.1e5,4.2e5,8.4e5 --out DIR
if (!exists("csv")) csv = 'sweep.csv'
if (!exists("out")) out = 'tear_opening_foundation.png'
set datafile separator ','
set terminal pngcairo size 1400,560 font ',11'
set output out
sigma = 80.8e3; t = 1.5e-3; nu = 0.48; a = 0.060   # pre-stress Pa, thickness m, half tear m
Epp(E) = E / (1 - nu**2)
ell(k, E) = sqrt(Epp(E) * t / k)
w(k, E) = 2 * sigma * ell(k, E) / Epp(E)
# Columns by name: the sweep's table has a header row.
K = 'material.attachment_stiffness'; Y = 'material.youngs_modulus'; W = 'metrics.physics.max_opening'
set multiplot layout 1,2
set logscale xy
set xlabel 'attachment stiffness k (Pa/m)'
set ylabel 'largest opening (mm)'
set key top right
set grid
set xrange [8e4:2e6]
set yrange [3:50]
set xtics ('1e5' 1e5, '2e5' 2e5, '4e5' 4e5, '8e5' 8e5, '1.6e6' 1.6e6)
set ytics (3, 5, 7, 10, 15, 20, 30, 40)
set title "tear-opening (resolution 1): points measured, lines 2{/Symbol s}l/E''"
plot for [i=0:2] csv using (column(Y) == 2.1e5 * 2**i ? column(K) : NaN):(column(W) * 1e3) \
       with points pt 7 ps 1.5 lc i+1 title sprintf('E = %.2f MPa', 0.21 * 2**i), \
     for [i=0:2] [1e5:1.6e6] w(x, 2.1e5 * 2**i) * 1e3 with lines lc i+1 dt 2 notitle
unset logscale y
set logscale x
set xlabel 'decay length l / half tear length a'
set ylabel "opening / (2{/Symbol s}l/E'')"
set xrange [0.2:3]
set xtics (0.25, 0.5, 1, 2)
set ytics auto
set yrange [0:1.1]
set key bottom left
set title 'the foundation limit holds where l << a (tear 12 cm, a = 6 cm)'
plot csv using (ell(column(K), column(Y)) / a):(column(W) / w(column(K), column(Y))) \
       with points pt 7 ps 1.5 lc 1 title 'measured', 1 with lines dt 2 lc 0 title 'foundation limit'
unset multiplot
