"""The README's Table II as the docs tests read it: {height [m]: {"sa": I_max, "mft": I_max}} [N s]."""
import re


def readme_table_ii(source):
    text = (source / "README.md").read_text()
    heights = [float(h) for h in re.search(r"\| z_B\^ref \[m\] \|(.*)\|", text).group(1).split("|")]
    cells = re.search(r"\| I_max SA-WBC / MFT-WBC \[N s\] \|(.*)\|", text).group(1).split("|")
    table = {}
    for h, cell in zip(heights, cells):
        sa, mft = (float(v) for v in cell.split("/"))
        table[h] = {"sa": sa, "mft": mft}
    return table
