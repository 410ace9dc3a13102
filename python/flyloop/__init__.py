"""flyloop: gymnasium environments over flyloop's MAVLink SITL."""

__version__ = "0.1.0"
