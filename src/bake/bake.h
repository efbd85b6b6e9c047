#pragma once
// Shadel baking: chart atlas ("shadel UVs") and triangle-ID maps per mesh.
