"""Guide curves and interpolated render hair: the frozen-hair engine runs on a few hundred
guides and tens of thousands of children follow them.

- :mod:`~hairtool.guides.binding`: the child definition (roots, guides and weights, variation)
  from guides and a scalp mesh, given roots, or a dense groom;
- :mod:`~hairtool.guides.children`: the children rebuilt from the guides' current shapes;
- :mod:`~hairtool.guides.render`: that plus ClumpWithGaps on the children, switchable;
- :mod:`~hairtool.guides.files`: render hair and its guides as two prims of one groom (USD
  purpose "guide"), and apart again;
- :mod:`~hairtool.guides.frames`, :mod:`~hairtool.guides.nearest`, :mod:`~hairtool.guides.surface`,
  :mod:`~hairtool.guides.scatter`: the frames, weights, surface distances and root scattering.
"""
