"""The messages a VTK algorithm sends, recorded for the Python tests."""
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.vtkConstants import VTK_STRING


def recorded(algorithm, *events):
    """The messages `algorithm` sends from now on with any of `events` ("ErrorEvent",
    "WarningEvent"), in order."""
    messages = []

    @calldata_type(VTK_STRING)
    def record(_caller, _event, message):
        messages.append(message)

    for event in events:
        algorithm.AddObserver(event, record)
    return messages
