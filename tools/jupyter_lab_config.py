"""Configuration of ``make lab`` (``jupyter lab --config=tools/jupyter_lab_config.py``).

* the chapters open unmodified (``tools/lab_contents.py``);
* the chapters' solutions fold as in the HTML book: JupyterLab's custom stylesheet
  (``--LabApp.custom_css``) from ``tools/jupyterlab-custom/custom.css``;
* kernels talk to the server over local IPC sockets instead of TCP on localhost: the kernel
  then starts without its warning "Kernel is running over TCP without encryption";
* the websockets' ping timeout equals their ping interval (no warning at the first connection).
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
# jupyter_server's websockets default to a ping timeout of three intervals (90 s for 30 s), which
# tornado 6.5 refuses with a warning at the first connection ("The websocket_ping_timeout (90000)
# cannot be longer than the websocket_ping_interval (30000)") and lowers to the interval: set so
c.ServerApp.tornado_settings = {"static_custom_path": [str(Path(ROOT) / "tools" / "jupyterlab-custom")],
                                "ws_ping_interval": 30000, "ws_ping_timeout": 30000}
