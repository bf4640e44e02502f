"""The LIGGGHTS material block of a parameter set, rendered with the decks' own macro."""

from collections.abc import Mapping
from typing import Any

from demcal.decks.render import template_environment
from demcal.particles.material import material_setup
from demcal.particles.size_distribution import size_distribution


def material_block_text(
    parameters: Mapping[str, float], settings: Mapping[str, Any], title: str
) -> str:
    """``fix property/global`` lines and the contact model for ``parameters``.

    Parameters
    ----------
    parameters : mapping
        coefficientFriction, coefficientRollingFriction, coefficientRestitution, density
        (and optionally cohesionEnergyDensity, wallFriction).
    settings : mapping
        The validated configuration (sections ``particles`` and ``material``).
    title : str
        First comment line of the block.
    """
    dist = size_distribution(settings["particles"])
    material = material_setup(dict(parameters), settings["material"], dist)
    env = template_environment()
    template = env.from_string(
        '{% import "_macros.j2" as m %}# {{ title }}\n{{ m.material_block(material) }}\n'
    )
    return template.render(material=material, title=title)
