"""Characters with hair bones (seed 001 as the paper applies it): glTF/VRM in, the anime cycle
and VRM spring bones on the hair chains, files out.

- :mod:`.read` (with :mod:`.accessors`, :mod:`.chains`, :mod:`.glb`) reads a character;
- :mod:`.model` holds it; :mod:`.skinning` poses its meshes;
- :mod:`.bundled` makes the character hairtool ships.
"""

from hairtool.character.model import Chain, Character, Collider, Joint, Nodes
from hairtool.character.read import load_character

__all__ = ["Chain", "Character", "Collider", "Joint", "Nodes", "load_character"]
