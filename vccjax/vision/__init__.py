"""Images of scenes: rendering (schematic and varied styles), parsing an image back into
a scene (OpenCV, the machine's `scene_parse` on pixels), and measuring that parse."""
