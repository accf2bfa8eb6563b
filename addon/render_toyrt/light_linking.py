"""Blender's light linking (4.0+) -> the core's light-linking sets: per instance a receiver set and a
blocker set (0-63), per light a mask of the receiver sets it lights and one of the blocker sets
whose objects shadow it (native lights/light_linking.h). Blender 3.x has no light linking: nothing
is computed and every mask stays full.

The sets are computed as Blender's dependency graph computes them for Cycles (facts from its
light-linking cache; docs/lights.md): each emitter's receiver (blocker) collection gets a bit,
emitters sharing a collection share it (at most 64 collections). Each object the collections
name collects, per collection, its link state (INCLUDE or EXCLUDE; the later entry wins when an
object is reached twice), and objects with the same include and exclude masks form one set,
numbered from 1 (set 0: objects no collection names; at most 63 more). An emitter lights (or is
shadowed by) the sets that include its collection, or every set when none does, minus the sets
that exclude it: so a collection with an INCLUDE entry lights only what it includes, one with
EXCLUDE entries alone everything else. An object in a nested collection takes the link state of
the child collection's entry in the emitter's collection.

Plain data in, plain data out (`link_sets`), so the rules are tested without Blender; `read_links`
reads the collections from a depsgraph."""
from __future__ import annotations

from dataclasses import dataclass, field

ALL = (1 << 64) - 1
MAX_COLLECTIONS = 64
MAX_SETS = 64  # set 0 is the default one


@dataclass(frozen=True)
class Emitter:
    """One emitter's collections as entries (object name, 'INCLUDE' or 'EXCLUDE'), in Blender's
    order; the collection's key (its name) says which emitters share one; None: no collection."""
    name: str
    receivers: tuple[tuple[str, str], ...] | None = None
    receivers_key: str | None = None
    blockers: tuple[tuple[str, str], ...] | None = None
    blockers_key: str | None = None


@dataclass
class LinkSets:
    """The core's light-linking data: set indices per object name (missing: 0) and masks per
    emitter name (missing: ALL). empty: no linking in the scene (nothing to send)."""
    receiver_set: dict[str, int] = field(default_factory=dict)
    blocker_set: dict[str, int] = field(default_factory=dict)
    receiver_sets: dict[str, int] = field(default_factory=dict)  # per emitter: the sets it lights
    blocker_sets: dict[str, int] = field(default_factory=dict)   # per emitter: the sets that shadow it
    notes: list[str] = field(default_factory=list)

    @property
    def empty(self) -> bool:
        return not (self.receiver_sets or self.blocker_sets)

    def instance_sets(self, name: str) -> tuple[int, int]:
        return self.receiver_set.get(name, 0), self.blocker_set.get(name, 0)


def _one_kind(emitters, entries_of, key_of, what, notes) -> tuple[dict[str, int], dict[str, int]]:
    """(set index per object, membership mask per emitter) for the receiver or blocker kind."""
    bits: dict[str, int] = {}
    emitter_bit: dict[str, int] = {}
    linked: set[str] = set()  # collections whose objects are linked (once per collection)
    masks: dict[str, list[int]] = {}  # object -> [include mask, exclude mask]
    for e in emitters:
        entries = entries_of(e)
        if entries is None:
            continue
        key = key_of(e)
        if key not in bits:
            if len(bits) >= MAX_COLLECTIONS:
                notes.append(f"light linking: more than {MAX_COLLECTIONS} {what} collections "
                             f"('{key}' and later are ignored, as in Cycles)")
                bits[key] = 0
            else:
                bits[key] = 1 << len(bits)
        bit = bits[key]
        if not bit:
            continue
        emitter_bit[e.name] = bit
        if key in linked:
            continue  # an emitter sharing the collection linked its objects already
        linked.add(key)
        for obj, state in entries:
            m = masks.setdefault(obj, [0, 0])
            if state == "INCLUDE":
                m[0] |= bit
                m[1] &= ~bit
            else:
                m[1] |= bit
                m[0] &= ~bit
    set_of_masks: dict[tuple[int, int], int] = {}
    object_set: dict[str, int] = {}
    included: dict[str, int] = {n: 0 for n in emitter_bit}
    excluded: dict[str, int] = {n: 0 for n in emitter_bit}
    for obj, (inc, exc) in masks.items():
        key = (inc, exc)
        if key not in set_of_masks:
            if len(set_of_masks) + 1 >= MAX_SETS:
                if len(set_of_masks) + 1 == MAX_SETS:
                    notes.append(f"light linking: more than {MAX_SETS - 1} {what} sets (the rest as unlinked)")
                set_of_masks[key] = -1
            else:
                set_of_masks[key] = len([v for v in set_of_masks.values() if v > 0]) + 1
        s = set_of_masks[key]
        if s < 0:
            continue
        object_set[obj] = s
        for name, bit in emitter_bit.items():
            if inc & bit:
                included[name] |= 1 << s
            if exc & bit:
                excluded[name] |= 1 << s
    membership = {name: (included[name] or ALL) & ~excluded[name] & ALL for name in emitter_bit}
    return object_set, membership


def link_sets(emitters: list[Emitter]) -> LinkSets:
    """The sets and masks of `emitters` (those with a receiver or blocker collection)."""
    out = LinkSets()
    if not emitters:
        return out
    out.receiver_set, out.receiver_sets = _one_kind(emitters, lambda e: e.receivers, lambda e: e.receivers_key,
                                                    "receiver", out.notes)
    out.blocker_set, out.blocker_sets = _one_kind(emitters, lambda e: e.blockers, lambda e: e.blockers_key,
                                                  "blocker", out.notes)
    return out


def _entries(collection) -> tuple[tuple[str, str], ...]:
    """A light-linking collection's objects with their link states, in Blender's order: the child
    collections first (each object in them, however deep, with the child entry's state), then
    the collection's own objects."""
    out = []

    def inner(coll, state):
        for child in coll.children:
            inner(child, state)
        for obj in coll.objects:
            out.append((obj.name, state))

    # collection_children / collection_objects hold the entries' settings in the order of the
    # collection's children / objects (the same lists in Blender).
    for child, entry in zip(collection.children, collection.collection_children):
        inner(child, entry.light_linking.link_state)
    for obj, entry in zip(collection.objects, collection.collection_objects):
        out.append((obj.name, entry.light_linking.link_state))
    return tuple(out)


def read_links(depsgraph) -> LinkSets:
    """The scene's light linking (Blender 4.0+; an empty LinkSets on 3.x or without links). Any
    object's collections count (a lamp's, or an emissive object's receiver collection); an
    emissive object's blocker collection is not followed in TOYRT: noted."""
    emitters, notes = [], []
    for obj in depsgraph.objects:
        ll = getattr(obj, "light_linking", None)
        if ll is None:
            return LinkSets()  # Blender 3.x: no light linking at all
        receivers, blockers = ll.receiver_collection, ll.blocker_collection
        if receivers is None and blockers is None:
            continue
        if obj.type != "LIGHT" and blockers is not None:
            notes.append(f"object '{obj.name}': shadow linking of an emissive object (every object shadows it)")
            blockers = None
            if receivers is None:
                continue
        emitters.append(Emitter(obj.name,
                                _entries(receivers) if receivers is not None else None,
                                receivers.name_full if receivers is not None else None,
                                _entries(blockers) if blockers is not None else None,
                                blockers.name_full if blockers is not None else None))
    out = link_sets(emitters)
    out.notes = notes + out.notes
    return out


def linked_light(spec, links: LinkSets, name: str):
    """A light spec (lights.py) with its light-linking masks from `links`."""
    from dataclasses import replace

    v = replace(spec.visibility, receiver_sets=links.receiver_sets.get(name, ALL),
                blocker_sets=links.blocker_sets.get(name, ALL))
    return replace(spec, visibility=v)
