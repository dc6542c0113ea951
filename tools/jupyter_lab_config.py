"""Configuration of ``make lab`` (``jupyter lab --config=tools/jupyter_lab_config.py``).

* the chapters open unmodified (``tools/lab_contents.py``);
* the chapters' solutions fold as in the HTML book: JupyterLab's custom stylesheet
  (``--LabApp.custom_css``) from ``tools/jupyterlab-custom/custom.css``;
* kernels talk to the server over local IPC sockets instead of TCP on localhost: the kernel
  then starts without its warning "Kernel is running over TCP without encryption";
* no websocket pings (``ws_ping_interval = 0``): the server and the browser are on one machine, and
  jupyter_server's pings, as configurable without a warning, closed every page's connection 30 s
  after it opened (below).
"""
import sys
from pathlib import Path

ROOT = str(Path(__file__).resolve().parents[1])
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

from tools.lab_contents import ChapterContentsManager  # noqa: E402

c = get_config()  # noqa: F821 (defined by traitlets when it loads this file)
c.ServerApp.contents_manager_class = ChapterContentsManager
c.KernelManager.transport = "ipc"
c.LabApp.custom_css = True
# jupyter_server pings each websocket every ws_ping_interval ms and closes it when no pong came for
# ws_ping_timeout ms; it checks that *before* its first ping, one interval after the connection
# opened, so a timeout of one interval closes every connection at 30 s (the page reconnects, and a
# Run All in progress then can wait forever for a reply lost meanwhile). Its default timeout (three
# intervals) works, but jupyter_server hands the same ms values to tornado as seconds, and tornado
# 6.5 warns at the first connection that a timeout may not exceed the interval. Without pings
# (interval 0) neither happens; a closed page closes its connection on this one machine anyway.
c.ServerApp.tornado_settings = {"static_custom_path": [str(Path(ROOT) / "tools" / "jupyterlab-custom")],
                                "ws_ping_interval": 0}
