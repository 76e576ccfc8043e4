"""ONNX post-processing so that OpenCV 4.6 DNN reads torch 1.13 exports."""

import onnx
from onnx import numpy_helper


def replace_identity_on_initializers(model):
    """Replaces each Identity node whose input is an initializer by a copy of
    that initializer under the node's output name (OpenCV 4.6 rejects such
    Identity nodes with "Identity ... inputs.size()").  Returns the count."""
    graph = model.graph
    inits = {i.name: i for i in graph.initializer}
    keep, replaced = [], 0
    for node in graph.node:
        if node.op_type == "Identity" and node.input[0] in inits:
            array = numpy_helper.to_array(inits[node.input[0]])
            graph.initializer.append(numpy_helper.from_array(array, node.output[0]))
            replaced += 1
        else:
            keep.append(node)
    del graph.node[:]
    graph.node.extend(keep)
    # Initializers listed as graph inputs confuse some readers: drop them.
    names = {i.name for i in graph.initializer}
    inputs = [i for i in graph.input if i.name not in names]
    del graph.input[:]
    graph.input.extend(inputs)
    return replaced
