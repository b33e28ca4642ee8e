"""What scripts/plot_evaluation.py and scripts/plot_compare.py share: matplotlib without a
display, the figures' resolution, and the command line `SCRIPT DIR`."""

import sys

import matplotlib

matplotlib.use("Agg")

DPI = 120


def run(argv, doc, draw):
    """`draw(DIR)` draws the figures of the folder DIR and returns the paths it wrote."""
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(doc.strip())
        return 0 if len(argv) == 2 else 2
    written = draw(argv[1])
    print("%s: wrote %s" % (argv[0].rsplit("/", 1)[-1], ", ".join(written)), file=sys.stderr)
    return 0
