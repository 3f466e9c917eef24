# style.gp — the look shared by every report figure (loaded by harness/report.py).
# The harness writes the terminal, output, title, labels and plot command; this file
# only sets styles, so changing the look of all figures happens here.
set grid back lc rgb '#d0d0d0' lw 0.6
set border 3 lc rgb '#404040'
set tics nomirror out scale 0.6
set key outside right top vertical Left reverse noautotitle samplen 2.5 spacing 1.1
set format y '%.4g'
set format x '%.6g'
set linetype 1 lc rgb '#1f77b4' lw 1.6
set linetype 2 lc rgb '#d62728' lw 1.6
set linetype 3 lc rgb '#2ca02c' lw 1.6
set linetype 4 lc rgb '#ff7f0e' lw 1.6
set linetype 5 lc rgb '#9467bd' lw 1.6
set linetype 6 lc rgb '#8c564b' lw 1.6
set linetype 7 lc rgb '#e377c2' lw 1.6
set linetype 8 lc rgb '#17becf' lw 1.6
set linetype cycle 8
