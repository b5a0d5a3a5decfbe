/**
 * @file extract.h
 * @brief The `chansph extract` command: profiles from stats.nc as CSV/TSV, in wall or outer
 *        units, optionally re-averaged over a range of the stored windows.
 */
#ifndef CHANSPH_EXTRACT_H
#define CHANSPH_EXTRACT_H

/**
 * @brief Run `chansph extract STATS.nc [--var a,b] [--units wall|outer] [--format csv|tsv]
 *        [--window T0:T1] [--pdfs]` and print to stdout (--pdfs: the one-point PDFs).
 * @param[in] argc,argv the command name ("extract", as getopt_long's program name) and
 *            its arguments
 * @return process exit code (0 success or --help, 1 input error)
 */
int extract_main(int argc, char **argv);

/**
 * @brief Run `chansph compare STATS.nc --dns FILE [--out DIR]` (stats/compare.py).
 * @param[in] argc,argv the arguments after the command name
 * @param[in] stats_dir directory of the python helpers
 * @return process exit code (only on failure to start python)
 */
int compare_main(int argc, char **argv, const char *stats_dir);

#endif
