"""Hairtool Studio's Qt widgets: the main window, the GL viewport, the tool dock and undo commands.

Data flows one way: widgets write to :class:`app.ui.scene.Scene`, the scene emits a signal only
when a value really changes, and widgets update themselves from it with their own signals blocked.
"""
