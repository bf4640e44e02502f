"""Pictures of the verification runs at the identified set: the settled heap, the shear cell at
the end of the pre-shear and mu(t) with the readout's steady windows."""

from collections.abc import Callable
from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.identification.figures import note_figure
from demcal.virtual_tests.pictures import heap_picture, mu_series_figure, shear_cell_picture


def _draw(draw: Callable[[Path, Path], Path], case_dir: Path, png: Path) -> None:
    # A failed verification run is reported in the verification table; it must not stop the
    # study, so its picture says why it is missing.
    try:
        draw(case_dir, png)
    except (ValueError, KeyError, OSError) as exc:
        print(f"no picture from {case_dir}: {exc}")
        note_figure(png, f"No picture: the verification run {case_dir.name} left no usable output.")


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]):
        heap_dir = Path(snakemake.input.angle_of_repose).parent
        shear_dir = Path(snakemake.input.shear_cell).parent
        _draw(heap_picture, heap_dir, Path(snakemake.output.heap))
        _draw(shear_cell_picture, shear_dir, Path(snakemake.output.shear_cell))
        _draw(mu_series_figure, shear_dir, Path(snakemake.output.mu_series))


main(snakemake)  # noqa: F821
