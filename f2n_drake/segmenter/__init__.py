"""DeepLabV3+ segmenter: network, weights, inference on images of any size."""
