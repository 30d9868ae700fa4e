"""The studio's document without Qt: what a project holds, edited only by commands on one undo
stack, observed by the widgets through plain callbacks (they never write to it another way).

:mod:`app.document.undo` is the stack (do, undo, merge for drags; "changed" is its clean
state), :mod:`app.document.capture` what a BVH capture is in the studio (its skeleton, its text
in a project, which frames its edits need as keys), :mod:`app.document.animation` the
animation side of the document and its commands, :mod:`app.document.project_io` the document
written out as a project and read back.
"""
