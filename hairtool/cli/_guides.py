"""Render-hair options shared by ``hairtool interpolate``, ``freeze``, ``simulate`` and
``anime`` (not a subcommand: the leading underscore keeps it out of the command list).

Children come from guides and a scalp mesh (``--scalp``), from guides alone (roots around the
guide roots), or ``--from-dense``: the input is a dense groom, ``--guides G`` strands of it are
chosen as guides and every strand is bound to them (along the surface of ``--scalp`` if
given). The engine, simulation or cycle runs on the guides and OUT receives the render
strands; in USD the guides go in the same file as a second prim of purpose ``guide``. The
guides also go to ``--guides-out`` (default: OUT with ``.guides`` before its extension,
``hair.usda`` → ``hair.guides.usda``) when it is given, from a dense groom, and for an
animation written to a format that cannot mark guides."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import TYPE_CHECKING

from hairtool.guides.limits import DEFAULT_FRIZZ, DEFAULT_K, DEFAULT_LENGTH_VARIATION

if TYPE_CHECKING:
    import numpy as np

    from hairtool.groom import Animation, Groom
    from hairtool.guides.binding import ChildBinding
    from hairtool.guides.prim_bindings import PrimBindings
    from hairtool.guides.render import RenderHair


#: Options that mean something only with --count or --from-dense (destination, flag).
_RENDER_ONLY = (
    ("scalp", "--scalp"), ("guides_per_child", "--guides-per-child"), ("vertices", "--vertices"),
    ("length_variation", "--length-variation"), ("frizz", "--frizz"), ("region", "--region"),
    ("density", "--density"), ("guides_out", "--guides-out"),
)  # fmt: skip


def add_arguments(
    parser: argparse.ArgumentParser, *, seed: bool = True, guides: bool = True
) -> argparse._ArgumentGroup:
    """The render-hair options; ``seed``/``guides`` False where the command has its own
    ``--seed`` (used for the children too) or ``--guides`` (anime: it also takes G there)."""
    g = parser.add_argument_group("render hair (children interpolated from guides)")
    g.add_argument("--count", type=int, default=None, help="children to grow from the guides")
    g.add_argument(
        "--scalp", metavar="MESH", default=None,
        help="scalp mesh the children grow on, a USD file (its Mesh prims, in its stage's up axis and unit) "
        "or an OBJ (in the groom's unit); freeze: also the head strokes collide with and slide on",
    )  # fmt: skip
    g.add_argument(
        "--scalp-up-axis", choices=("y", "z"), default=None,
        help="the up axis of an OBJ --scalp (default: the groom's; Blender's OBJ export is y, its USD z)",
    )  # fmt: skip
    g.add_argument(
        "--guides-per-child", type=int, metavar="K", help=f"k nearest guides (default {DEFAULT_K})"
    )
    if seed:
        g.add_argument(
            "--seed", type=int, default=0, help="seed of the roots and variation (same seed, same bytes)"
        )
    g.add_argument("--vertices", type=int, default=None, help="vertices per child (default: the guides')")
    g.add_argument(
        "--length-variation",
        type=float,
        default=None,
        help=f"child lengths ×[1−v, 1+v], v in [0, 0.9] (default {DEFAULT_LENGTH_VARIATION})",
    )
    g.add_argument(
        "--frizz",
        type=float,
        default=None,
        help=f"curl radius at the tip / child length, [0, 0.5] (default {DEFAULT_FRIZZ})",
    )
    g.add_argument(
        "--region",
        metavar="SET|FACES",
        default=None,
        help="where hair grows: a face set (OBJ group) or triangle indices",
    )
    g.add_argument(
        "--density", metavar="FILE", default=None, help="density per triangle or vertex (.npy or text)"
    )
    g.add_argument(
        "--clump-children",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="ClumpWithGaps among the children (default: on for grown children, off for authored "
        "hair: --from-dense, or render hair read beside its guides)",
    )
    g.add_argument(
        "--from-dense", action="store_true", help="the input is a dense groom: pick --guides G of it"
    )
    if guides:
        g.add_argument(
            "--guides", type=int, default=None, metavar="G", help="guides to pick with --from-dense"
        )
    g.add_argument(
        "--guides-out",
        default=None,
        metavar="PATH",
        help="write the guides here too (default OUT.guides.EXT, where they go apart)",
    )
    return g


def wanted(args: argparse.Namespace) -> bool:
    """Whether the options ask for render hair, or the input brought its own
    (:func:`input_groom`)."""
    return args.count is not None or args.from_dense or getattr(args, "bound_hair", None) is not None


def input_groom(args: argparse.Namespace, groom: Groom) -> Groom:
    """The strands the command works on, from an input that may hold render hair and its guides
    (two prims, the guides of purpose ``guide``, as this tool writes them): the guides, to grow
    new children from (``--count``); the render hair, to pick new guides from
    (``--from-dense``); otherwise the guides, with the render hair bound to them exactly
    (``args.bound_hair``), so that it follows what the command does to them."""
    from hairtool.guides.files import split_guides

    hair, guides = split_guides(groom)
    args.bound_hair = None
    if guides is None:
        return groom
    if args.from_dense:
        return hair
    if args.count is None:
        args.bound_hair = hair
    return guides


def prepare(
    args: argparse.Namespace, groom: Groom, *, keep_hair: bool = True
) -> tuple[Groom, ChildBinding | PrimBindings | None, float]:
    """What a command works on, from its input: :func:`input_groom`, then :func:`bind` where
    the options ask for render hair or the input brought its own (``keep_hair`` False: a run
    that writes none, which works on the guides alone); guides on several hair prims are bound
    prim by prim (:func:`bind_prims`). ``(groom, binding or None, bind milliseconds)``, the
    groom being the guides where there is a binding."""
    groom = input_groom(args, groom)
    if not keep_hair:
        args.bound_hair = None
    if _per_prim(args, groom):
        return bind_prims(args, groom)
    if not wanted(args):
        if args.clump_children:  # (known only now: the input may have brought render hair)
            from hairtool.errors import ParameterError

            raise ParameterError(
                "clump-children",
                True,
                "--clump-children with --count N, --from-dense or render hair in the input",
            )
        return groom, None, 0.0
    return bind(args, groom)


def _per_prim(args: argparse.Namespace, groom: Groom) -> bool:
    """Whether ``--count`` grows each hair prim's children on its own (:mod:`hairtool.prims`):
    guides on several prims, none of them guides already (render hair read beside its guides
    keeps its binding), children grown around the guide roots."""
    from hairtool.errors import ParameterError
    from hairtool.prims import split

    prims = groom.metadata.for_strands(groom.strand_count).curves
    several = len(split(groom)) > 1 and all(c.purpose != "guide" for c in prims)
    if not several or getattr(args, "bound_hair", None) is not None:
        return False
    if args.from_dense or args.scalp is not None:  # (interpolate and freeze pick the prim first)
        flag = "--scalp" if args.scalp is not None else "--from-dense"
        paths = ", ".join(c.path for c in prims[:4]) + (" …" if len(prims) > 4 else "")
        raise ParameterError(
            flag[2:], args.scalp if args.scalp is not None else True,
            f"one hair prim for {flag}, which belongs to one ({args.input} holds {paths}; "
            "interpolate --prim PATH grows one prim's children)",
        )  # fmt: skip
    return args.count is not None


def bind_prims(args: argparse.Namespace, groom: Groom) -> tuple[Groom, PrimBindings, float]:
    """``(guides, one binding per prim, milliseconds)``: each prim's children bound to its own
    guides, ``--count`` shared between the prims (:mod:`hairtool.guides.prim_bindings`)."""
    import copy

    from hairtool.guides.prim_bindings import bind_per_prim

    t0 = time.perf_counter()

    def one(part: Groom, n: int) -> ChildBinding:
        each = copy.copy(args)
        each.count = n
        return bind(each, part)[1]

    return groom, bind_per_prim(groom, args.count, one), (time.perf_counter() - t0) * 1e3


def guides_path(args: argparse.Namespace) -> Path:
    from hairtool.guides.files import guides_path_for

    return Path(args.guides_out) if args.guides_out else guides_path_for(args.output)


def check(
    args: argparse.Namespace,
    *,
    animated: bool = False,
    guides_option: bool = True,
    required: bool = False,
    input_hair: bool = True,
) -> None:
    """Refuse contradictory options, options that would do nothing, and unwritable outputs,
    before any work (``animated``: the output is an animation, whose guides go beside it in
    formats other than USD; ``guides_option`` False where ``--guides`` is the command's own and
    means something without ``--from-dense``; ``required``: the command makes render hair or
    nothing; ``input_hair`` False: there is no input file that could bring render hair of its
    own, so ``--clump-children`` alone is refused here too, not only in :func:`prepare`)."""
    from hairtool import io
    from hairtool.errors import ParameterError
    from hairtool.guides.scalp_file import check_up_axis

    check_up_axis(args.scalp, getattr(args, "scalp_up_axis", None))
    if required and not wanted(args):
        raise ParameterError("count", None, "a number of children (or --from-dense --guides G)")
    if not wanted(args):
        options = _RENDER_ONLY + ((("guides", "--guides"),) if guides_option else ())
        options += () if input_hair else (("clump_children", "--clump-children"),)
        for dest, flag in options:
            if getattr(args, dest) not in (None, False):
                value = getattr(args, dest)
                raise ParameterError(flag[2:], value, f"{flag} only with --count N or --from-dense")
        return
    if args.from_dense:
        if args.guides is None:
            raise ParameterError("guides", None, "a number of guides to pick with --from-dense")
        if args.count is not None:
            raise ParameterError("from-dense", "with --count", "either --from-dense or --count")
        if args.region is not None or args.density is not None:
            raise ParameterError("from-dense", "with --region/--density", "the dense strands' own roots")
        for dest in ("vertices", "length_variation", "frizz"):
            value = getattr(args, dest)
            if value is not None:
                expected = "none with --from-dense (strands keep theirs)"
                raise ParameterError(dest.replace("_", "-"), value, expected)
    elif guides_option and args.guides is not None:
        raise ParameterError("guides", args.guides, "none without --from-dense (IN's strands are the guides)")
    if args.density is not None and args.scalp is None:
        raise ParameterError("density", args.density, "a --scalp mesh whose triangles or vertices it weights")
    if args.region is not None and args.scalp is None:
        raise ParameterError("region", args.region, "a --scalp mesh to select triangles of")
    io.format_for(args.output, writing=True)
    if args.from_dense or args.guides_out or (animated and not is_usd(args.output)):
        io.format_for(guides_path(args), writing=True)


def _numbers(path: str, what: str) -> np.ndarray:
    import numpy as np

    from hairtool.errors import FormatError

    p = Path(path)
    if not p.is_file():
        raise FormatError(p, "no such file")
    try:
        a = np.load(p, allow_pickle=False) if p.suffix == ".npy" else np.loadtxt(p, ndmin=1)
    except (OSError, ValueError) as e:
        raise FormatError(p, f"cannot read {what}: {e}") from None
    return np.asarray(a).reshape(-1)


def bind(args: argparse.Namespace, groom: Groom) -> tuple[Groom, ChildBinding, float]:
    """``(guides, binding, milliseconds)`` from the options and the input groom."""
    import numpy as np

    from hairtool.errors import ParameterError
    from hairtool.guides.binding import bind_dense, bind_roots, bind_scalp, bind_to_guides

    t0 = time.perf_counter()
    # (by default no more guides than there are: a prim of eyebrows may have three)
    k = min(DEFAULT_K, groom.strand_count) if args.guides_per_child is None else args.guides_per_child
    lv = DEFAULT_LENGTH_VARIATION if args.length_variation is None else args.length_variation
    shape = {"length_variation": lv, "frizz": DEFAULT_FRIZZ if args.frizz is None else args.frizz}
    mesh = None
    if args.scalp is not None:
        from hairtool.guides.scalp_file import load_scalp

        mesh = load_scalp(args.scalp, groom, getattr(args, "scalp_up_axis", None))
    if getattr(args, "bound_hair", None) is not None:
        guides, binding = groom, bind_to_guides(args.bound_hair, groom, k=k, mesh=mesh)
    elif args.from_dense:
        guides, binding = bind_dense(groom, args.guides, k=k, seed=args.seed, mesh=mesh)
    elif mesh is not None:
        region = None
        if args.region is not None and not Path(args.region).is_file():
            region = args.region  # the name of a face set (group) of the mesh's file
        elif args.region is not None:
            region = _numbers(args.region, "triangle indices")
            if not np.all(region == np.round(region)):
                raise ParameterError("region", args.region, "whole triangle indices")
            region = region.astype(np.int64)
        density = None if args.density is None else _numbers(args.density, "densities")
        guides = groom
        binding = bind_scalp(
            groom, mesh, args.count, k=k, vertices=args.vertices, seed=args.seed, region=region,
            density=density, **shape,
        )  # fmt: skip
    else:
        guides = groom
        binding = bind_roots(groom, count=args.count, k=k, vertices=args.vertices, seed=args.seed, **shape)
    return guides, binding, (time.perf_counter() - t0) * 1e3


def render(args: argparse.Namespace, binding: ChildBinding) -> RenderHair:
    """The children, clumped as ``--clump-children`` says (by default grown children are and
    authored hair is not, as in the studio:
    :func:`~hairtool.guides.binding.clumps_by_default`): at their own automatic radius (they
    are far denser than the guides), with the command's clump passes, gap mode and length rule
    where it has them (``freeze``: ``--clump-iterations``, ``--gap-mode``, ``--keep-lengths``),
    else three passes, printed gaps and lengths kept."""
    from hairtool.guides.binding import clumps_by_default
    from hairtool.guides.render import ChildClump, RenderHair

    on = clumps_by_default(binding) if args.clump_children is None else args.clump_children
    if not on:
        return RenderHair(binding, None)
    clump = ChildClump(
        iterations=getattr(args, "clump_iterations", 3),
        gap_mode=getattr(args, "gap_mode", "printed"),
        seed=args.seed,
        keep_lengths=getattr(args, "keep_lengths", True),
    )
    return RenderHair(binding, clump)


def is_usd(path: str | Path) -> bool:
    from hairtool import io

    return io.format_for(path, writing=True).module == "usd"


def write(args: argparse.Namespace, hair: Groom, guides: Groom) -> dict:
    """Write the render strands: to USD with the guides as a second prim of purpose ``guide``
    (:mod:`hairtool.guides.files`), elsewhere alone; the guides also go to ``--guides-out``
    when it is given and from a dense groom. The report's paths."""
    from hairtool import io
    from hairtool.guides.files import with_guides

    io.write(args.output, with_guides(hair, guides) if is_usd(args.output) else hair)
    report = {"output": str(args.output)}
    if args.from_dense or args.guides_out:
        io.write(guides_path(args), guides)
        report["guides_output"] = str(guides_path(args))
    return report


def write_animation(args: argparse.Namespace, binding: ChildBinding, guides: Animation) -> dict:
    """Write the render-hair animation of an animation of the guides (a simulation, a cycle):
    :func:`hairtool.guides.files.write_animation` (USD: children + guide prim, streamed; other
    formats: the guides animation in ``--guides-out``, also written from a dense groom or when
    given)."""
    from hairtool.guides.animate import RenderHairAnimation
    from hairtool.guides.files import write_animation
    from hairtool.guides.prim_bindings import PrimBindings

    if isinstance(binding, PrimBindings):
        return _write_prims_animation(args, binding, guides)
    hair = RenderHairAnimation(binding, guides, render(args, binding).clump)
    t0 = time.perf_counter()
    side = guides_path(args) if args.from_dense or args.guides_out or not is_usd(args.output) else None
    report = write_animation(args.output, hair, guides_path=side)
    return report | {
        "guides": guides.strand_count,
        "children": binding.child_count,
        "child_vertices": binding.vertex_count,
        "render_seconds": round(time.perf_counter() - t0, 4),
    }


def _write_prims_animation(args: argparse.Namespace, bindings: PrimBindings, guides: Animation) -> dict:
    """:func:`write_animation` of children bound prim by prim: each prim's children follow its
    own guides and go to its own render prim, the prims end to end in the source's order."""
    from hairtool import io
    from hairtool.guides.prim_bindings import prim_frames
    from hairtool.io import usd

    t0 = time.perf_counter()
    usd_out = is_usd(args.output)
    side = guides_path(args) if args.guides_out or not usd_out else None
    if side is not None:
        io.format_for(side, writing=True)  # refused before the long part
    frames, _ = prim_frames(bindings, guides, lambda b: render(args, b).clump, with_guides=usd_out)
    if usd_out:
        usd.write(Path(args.output), frames)
    else:
        io.write(args.output, frames.animation())
    report = {"output": str(args.output)}
    if side is not None:
        io.write(side, guides)
        report["guides_output"] = str(side)
    return report | {
        "guides": guides.strand_count,
        "children": bindings.child_count,
        "child_vertices": bindings.vertex_count,
        "render_seconds": round(time.perf_counter() - t0, 4),
    }


def primvar_pairs(guides: Groom, binding: ChildBinding | None, *, written: bool = False) -> list:
    """``(guide prim, render prim, binding)`` of one prim's children, for their primvars
    (:mod:`hairtool.guides.child_primvars`); none without children or for guides without a
    prim of their own. ``written``: the guide prim as OUT holds it (where the guides' own
    primvars were given to the strands strokes left: :func:`carry_planted`), not the source's."""
    from hairtool.guides.files import render_prims
    from hairtool.guides.prim_bindings import PrimBindings

    if isinstance(binding, PrimBindings):  # each prim's guides are its binding's rest guides
        return [x for b in binding.bindings for x in primvar_pairs(b.rest_guides, b, written=written)]
    own = guides.metadata.for_strands(guides.strand_count).curves
    if binding is None or len(own) != 1:
        return []
    hair, kept = render_prims(binding.metadata, binding.child_count, guides.metadata, guides.strand_count)
    return [((kept[0] if written else own[0]).path, hair[0].path, binding)]


def carry(args: argparse.Namespace, pairs: list = ()) -> None:
    """USD IN to USD OUT: the scene beside the hair (:mod:`hairtool.io.usd_carry`), and each
    guide prim's primvars on its children (``pairs``: :func:`primvar_pairs`)."""
    from hairtool.io.usd_carry import USD_SUFFIXES, carry_between

    carry_between(args.input, args.output)
    if pairs and all(Path(p).suffix.lower() in USD_SUFFIXES for p in (args.input, args.output)):
        from hairtool.guides.child_primvars import give_children_primvars
        from hairtool.io.usd import _diagnosed

        _diagnosed(Path(args.input), lambda: give_children_primvars(args.input, args.output, list(pairs)))


def carry_planted(args: argparse.Namespace, changed: list, pairs: list = ()) -> None:
    """USD IN to USD OUT, after :func:`carry`: the primvars of each prim whose strands strokes
    planted or removed (``changed``: ``(prim, strands before, pipeline)``), given to the strands
    it has now (:mod:`hairtool.guides.strand_primvars`), then those of the guides OUT now holds
    on their children (``pairs``: :func:`primvar_pairs` with ``written``)."""
    from hairtool.io.usd_carry import USD_SUFFIXES

    if not all(Path(p).suffix.lower() in USD_SUFFIXES for p in (args.input, args.output)):
        return
    from hairtool.guides.strand_primvars import give_strands_primvars
    from hairtool.io.usd import _diagnosed

    # (with children, the one prim's guides are where OUT holds them: its first pair's guide prim)
    prims = [
        (prim.path, pairs[0][0] if pairs else prim.path, pipe.origin, was, pipe.result)
        for prim, was, pipe in changed
    ]
    _diagnosed(Path(args.input), lambda: give_strands_primvars(args.input, args.output, prims))
    if pairs:
        from hairtool.guides.child_primvars import give_children_primvars

        _diagnosed(Path(args.output), lambda: give_children_primvars(args.output, args.output, list(pairs)))
