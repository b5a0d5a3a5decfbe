"""chansph-stats TOOL [ARGS...]: run one analysis tool of the chansph_stats package.

`TOOL --help` describes each tool.
"""
import importlib
import sys

from . import cli

# tool name: (module, one line); "module:function" where one module holds several tools (else
# the function is main)
TOOLS = {
    "compare": ("compare", "profiles of a run (stats.nc) against a DNS set (`chansph compare`)"),
    "windows": ("windows", "per-window turbulence indicators of a run"),
    "window_peaks": ("window_peaks", "Reynolds-stress peaks over time ranges against a DNS"),
    "ab_table": ("ab_table", "A/B table of turbulent runs"),
    "ab_score": ("ab_score", "scored A/B table: redistribution, pressure noise, peaks, cost"),
    "error_vs_time": ("error_vs_time", "error against the DNS window group by window group"),
    "convergence": ("convergence", "running averages and their standard errors against run time, "
                    "with the projection to a target error"),
    "blocking": ("blocking", "blocking analysis: the standard errors against the batch length"),
    "resolution_extrapolate": ("resolution_extrapolate",
                               "the resolution a series extrapolates to"),
    "plot_profile": ("plot_profile", "u_mean of a laminar run against the analytical profile"),
    "dns_c_table": ("dns_c_table", "write solver/dns_lm180.h from the Lee & Moser table"),
    "ckpt": ("ckpt_info", "summarise checkpoints (format, step, time, particles)"),
    "pdf_compare": ("pdf_compare", "one-point PDFs of u', v', w' against MKM Re_tau = 180"),
    "spectra_compare": ("twopoint_compare:spectra_main",
                        "1-D spectra in x and z against MKM Re_tau = 180"),
    "corr_compare": ("twopoint_compare:corr_main",
                     "two-point correlations in x and z against MKM Re_tau = 180"),
    "skewflat_compare": ("skewflat_compare", "skewness and flatness profiles against MKM 180"),
    "rs_budget": ("budget_compare", "Reynolds-stress budgets (rsb_*) against the MKM 180 balances"),
    "lagr_check": ("lagr_check", "the Lagrangian engine against exact dispersion laws"),
    "lagr_table": ("lagr_table", "Lagrangian and quadrant statistics with their errors (tables)"),
    "figures": ("figures", "the five profiles in one figure and the budgets, redrawn from stats.nc"),
    "summary": ("summary", "one screen: is a run turbulent, its peaks against a DNS (quick-start)"),
}


USAGE = "usage: chansph-stats TOOL [ARGS...]   (--help: the tools; TOOL --help: its options)"


def tool_list():
    return "tools:\n" + "\n".join("  %-24s %s" % (name, line) for name, (_, line) in TOOLS.items())


def main(argv=None, prog="chansph-stats"):
    """Run the tool argv[0] with argv[1:]; returns its exit status."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in ("-h", "--help"):
        print(__doc__.split("\n")[0] + "\n" + USAGE + "\n" + tool_list())
        return 0
    if not argv or argv[0] not in TOOLS:
        print("error: %s\n%s" % ("unknown tool '%s'" % argv[0] if argv else "no tool given",
                                 USAGE), file=sys.stderr)
        return 1
    module, _, function = TOOLS[argv[0]][0].partition(":")
    tool = importlib.import_module("." + module, __package__)
    return cli.run(getattr(tool, function or "main"), argv[1:], "%s %s" % (prog, argv[0])) or 0


if __name__ == "__main__":
    sys.exit(main())
