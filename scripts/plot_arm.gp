# Plot of one `recruit simulate` run of an arm task: elbow angle and reference (top), flexor and
# extensor forces and their references (middle), on-counts (bottom). Call with
#   gnuplot -e "csv='steps.csv'; out='plot.png'; title='...'" scripts/plot_arm.gp
if (!exists("csv")) csv = 'steps.csv'
if (!exists("out")) out = 'plot.png'
if (!exists("title")) title = ''
set terminal png size 900,800 font ',10' noenhanced
set output out
set datafile separator ','
set datafile columnheaders
set key top right opaque
set grid lc rgb '#dddddd'
set lmargin 10
set multiplot layout 3,1 title title
deg = 180 / pi
set ylabel 'elbow angle (deg)'
plot csv every 10 using 'time':(column('reference') * deg) with lines lw 2 lc rgb '#555555' \
       title 'reference', \
     csv every 10 using 'time':(column('angle') * deg) with lines lw 1.5 lc rgb '#d62728' \
       title 'angle'
set ylabel 'tension (N)'
plot csv every 10 using 'time':'flexor.force' with lines lw 1.5 lc rgb '#d62728' title 'flexor', \
     csv every 10 using 'time':'flexor.force_reference' with steps dt 2 lc rgb '#d62728' \
       title 'flexor reference', \
     csv every 10 using 'time':'extensor.force' with lines lw 1.5 lc rgb '#1f77b4' \
       title 'extensor', \
     csv every 10 using 'time':'extensor.force_reference' with steps dt 2 lc rgb '#1f77b4' \
       title 'extensor reference'
set ylabel 'units on'
set xlabel 'time (s)'
plot csv every 10 using 'time':'flexor.true_on' with steps lw 1.5 lc rgb '#d62728' \
       title 'flexor on', \
     csv every 10 using 'time':'extensor.true_on' with steps lw 1.5 lc rgb '#1f77b4' \
       title 'extensor on'
unset multiplot
