"""ISO 9283: pose repeatability and accuracy figures, and the test cube placed on a robot."""
