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


def remove_zero_pads(model):
    """Removes constant Pad nodes whose pads are all zero (torch emits one before each
    AveragePool of the pyramid pooling): OpenCV 4.6 runs each as a copy of the 160-channel
    map.  Their consumers read the Pad's input instead.  Returns the count."""
    graph = model.graph
    rename, keep = {}, []
    for node in graph.node:
        attrs = {a.name: onnx.helper.get_attribute_value(a) for a in node.attribute}
        if (node.op_type == "Pad" and len(node.input) == 1
                and attrs.get("mode", b"constant") == b"constant"
                and not any(attrs.get("pads", [1]))):
            rename[node.output[0]] = node.input[0]
        else:
            keep.append(node)
    outputs = {o.name for o in graph.output}
    if outputs & rename.keys():
        raise ValueError("a zero Pad produces a graph output")
    for node in keep:
        for i, name in enumerate(node.input):
            while name in rename:
                name = rename[name]
            node.input[i] = name
    del graph.node[:]
    graph.node.extend(keep)
    return len(rename)
