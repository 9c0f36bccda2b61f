from tests.support.widgets import drive, frames
def test_dbg(viewer):
    viewer.set_panel("surfaces")
    frames(viewer, 2)
    print(viewer.state.errors)
    print([k for k in viewer.ui.plots if k[0]=="surfaces"])
    print([k for k in viewer.ui.seen if k[0]=="surfaces"])
