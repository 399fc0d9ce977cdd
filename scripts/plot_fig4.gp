# Plots the Fig. 4 step response of the isometric bench from sma_fig4_step's CSV.
# Usage: gnuplot -e "csv='fig4.csv'; out='docs/img/fig4_step.png'" scripts/plot_fig4.gp
if (!exists("csv")) csv = 'fig4.csv'
if (!exists("out")) out = 'docs/img/fig4_step.png'
set datafile separator ','
set terminal pngcairo size 900,700 font 'Sans,10'
set output out
set multiplot layout 2,1 title "Isometric bench, 60 SMA units: all switched on at t = 1 s, off at t = 12 s"
set grid
set key top right
set ylabel 'force (N)'
set yrange [0:32]
set xrange [0:20]
set arrow 1 from 1,0 to 1,32 nohead dt 3 lc rgb '#888888'
set arrow 2 from 12,0 to 12,32 nohead dt 3 lc rgb '#888888'
# Paper's Fig. 4 band: about 25-30 N after about 5 s
set object 1 rect from 6,25 to 12,30 fc rgb '#ddeeff' fs solid 0.5 noborder behind
set label 1 "paper: 25-30 N" at 6.2,31 font 'Sans,9'
plot csv using 1:2 skip 1 with lines lw 2 lc rgb '#c04000' title 'bundle tension (plugin)', \
     csv using 1:6 skip 1 every 20 with points pt 7 ps 0.3 lc rgb '#0060c0' title 'load cell: k x', \
     csv using 1:($3*0.5) skip 1 with steps lc rgb '#606060' dt 2 title 'units on (scaled: 60 -> 30)'
unset object 1
unset label 1
set ylabel 'mean temperature (C)'
set y2label 'mean martensite fraction xi'
set yrange [0:200]
set y2range [0:1.05]
set ytics nomirror
set y2tics
set xlabel 'time (s)'
set key center right
set arrow 1 from 1,0 to 1,200 nohead dt 3 lc rgb '#888888'
set arrow 2 from 12,0 to 12,200 nohead dt 3 lc rgb '#888888'
plot csv using 1:4 skip 1 with lines lw 2 lc rgb '#c00000' title 'mean temperature', \
     csv using 1:5 skip 1 axes x1y2 with lines lw 2 lc rgb '#0040a0' title 'mean xi'
unset multiplot
