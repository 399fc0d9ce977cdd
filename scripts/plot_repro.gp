# Plot of one `recruit simulate` run of a force task: force and reference (top), true and
# estimated on-count (bottom). Call with
#   gnuplot -e "csv='steps.csv'; out='plot.png'; title='...'" scripts/plot_repro.gp
# Columns are found by name in the CSV header (docs/formats/task.md).
if (!exists("csv")) csv = 'steps.csv'
if (!exists("out")) out = 'plot.png'
if (!exists("title")) title = ''
if (!exists("bundle")) bundle = 'bundle'
set terminal png size 900,640 font ',10' noenhanced
set output out
set datafile separator ','
set datafile columnheaders
set key top right opaque
set grid lc rgb '#dddddd'
set multiplot layout 2,1 title title
set lmargin 10
set ylabel 'force (N)'
set xrange [0:*]
plot csv every 10 using 'time':'reference' with lines lw 2 lc rgb '#555555' title 'reference', \
     csv every 10 using 'time':'measured' with lines lw 1.5 lc rgb '#d62728' title 'force'
set ylabel 'units on'
set xlabel 'time (s)'
set yrange [0:62]
plot csv every 10 using 'time':(column(bundle.'.true_on')) with steps lw 1.5 lc rgb '#1f77b4' \
       title 'true on-count', \
     csv using 'time':(column('control_instant') > 0 ? column(bundle.'.estimated_on') : 1/0) \
       with points pt 7 ps 0.35 lc rgb '#ff7f0e' title 'estimated on-count (at control instants)'
unset multiplot
